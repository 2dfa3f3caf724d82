"""The five models of both FMU families: their names, slave scripts and default folder."""
from pathlib import Path

__all__ = ["FMU_SCRIPTS", "DEFAULT_FMU_DIR", "DEFAULT_SIGNALS_SCENARIO", "default_fmu_paths"]

FMU_SCRIPTS = {"SmaActuator": "sma_actuator.py", "SmaFeedforward": "sma_feedforward.py",
               "SmaPiController": "sma_pi_controller.py", "SmaPwmDriver": "sma_pwm_driver.py",
               "SmaScenarioSignals": "sma_scenario_signals.py"}
DEFAULT_FMU_DIR = Path("fmus")
DEFAULT_SIGNALS_SCENARIO = "load-step-pi+ff-adaptive"  # the paper's Fig. 10 signals


def default_fmu_paths(out_dir=DEFAULT_FMU_DIR):
    """{model name: path} where the build puts the FMUs."""
    return {name: Path(out_dir) / f"{name}.fmu" for name in FMU_SCRIPTS}
