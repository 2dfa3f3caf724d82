"""The fmpy co-simulation master: SmaActuator (+ SmaFeedforward, + SmaPwmDriver) FMUs in the closed loop.

Built on fmpy's ``FMU2Slave`` (through :class:`~sma_fmu.fmi.instance.FmuInstance`). The
loop and the PI block are those of :mod:`sma_fmu.cosim.loop`; the compensator FMU is
stepped before the plant (Gauss-Seidel), so u_ff,k reaches the plant's step k. A scenario
with a PWM drive puts the SmaPwmDriver FMU between the PI and the plant, stepped after the
PI and before the plant in the same step: the plant gets the wave's mean over that step.
"""
import time
from pathlib import Path

from sma_fmu.cosim.loop import PLANT_OUTPUTS, LoopResult, run_loop
from sma_fmu.fmi.build import DEFAULT_FMU_DIR, default_fmu_paths, read_description
from sma_fmu.fmi.slave_support.choices import choice_code
from sma_fmu.fmi.instance import FmuError, FmuInstance

__all__ = ["FmuPlant", "FmuCompensator", "FmuDriver", "needed_fmus", "run_fmus", "MissingFmuError",
           "model_parameter_values"]


class MissingFmuError(FileNotFoundError):
    """A needed FMU has not been built."""


def model_parameter_values(fmu_path, params, variables=None):
    """Start values for every wire parameter the FMU exposes, from ``params``.

    ``variables``: the FMU's model variables if already read (else they are read from
    ``fmu_path``).
    """
    values = params.values()
    variables = read_description(fmu_path).modelVariables if variables is None else variables
    return {v.name: values[v.name] for v in variables
            if v.causality == "parameter" and v.name in values}


class FmuPlant:
    """The SmaActuator FMU as a loop plant."""

    def __init__(self, scenario, fmu_path, instance_name="plant"):
        start = model_parameter_values(fmu_path, scenario.params)
        start.update(T_start=scenario.T_start,
                     hysteresis_mode=choice_code("hysteresis_mode", scenario.hysteresis_mode),
                     load=scenario.load.value(0.0))
        self.fmu = FmuInstance(fmu_path, instance_name, start)
        self._inputs = self.fmu.port(("P_in", "load"))
        self._outputs = self.fmu.port(PLANT_OUTPUTS)

    def outputs(self):
        """The loop's :data:`~sma_fmu.cosim.loop.PLANT_OUTPUTS` now."""
        return self._outputs.get()

    def step(self, time_s, power, load, step_size):
        """Set P_in and load, doStep, return the PLANT_OUTPUTS at the end of the step."""
        self._inputs.set((power, load))
        self.fmu.step(time_s, step_size)
        return self._outputs.get()

    def close(self):
        """Free the instance."""
        self.fmu.close()


class FmuCompensator:
    """The SmaFeedforward FMU as the loop's compensator."""

    def __init__(self, scenario, fmu_path, instance_name="feedforward"):
        c = scenario.controller
        start = model_parameter_values(fmu_path, scenario.compensator_params)
        start.update(alpha=c.alpha, beta=c.beta, model_load=c.model_load,
                     adapt_to_load=c.adapt_to_load, inverse=choice_code("inverse", c.inverse),
                     R_ref=scenario.reference.value(0.0),
                     load=scenario.load.value(0.0))
        self.fmu = FmuInstance(fmu_path, instance_name, start)
        self._inputs = self.fmu.port(("R_ref", "load"))
        self._outputs = self.fmu.port(("P_ff", "T_ref"))
        self._saturated = self.fmu.port(("saturated",))

    def step(self, time_s, reference, load, step_size):
        """Set R_ref and load, doStep, return (P_ff, T_ref, saturated) for this sample."""
        self._inputs.set((reference, load))
        self.fmu.step(time_s, step_size)
        p_ff, t_ref = self._outputs.get()
        return p_ff, t_ref, self._saturated.get()[0] != 0

    def close(self):
        """Free the instance."""
        self.fmu.close()


class FmuDriver:
    """The SmaPwmDriver FMU as the loop's driver (the hook of :func:`~sma_fmu.cosim.loop.run_loop`)."""

    def __init__(self, scenario, fmu_path, instance_name="driver"):
        drive = scenario.drive
        self.fmu = FmuInstance(fmu_path, instance_name,
                               {"frequency_Hz": drive.frequency_Hz, "peak_W": drive.peak_W})
        self._inputs = self.fmu.port(("P_demand",))
        self._outputs = self.fmu.port(("P_in",))

    def initial(self):
        """P_in [W] after initialization, before the first step (0 W)."""
        return self._outputs.get()[0]

    def step(self, time_s, demand, step_size):
        """Set P_demand [W], doStep, return P_in [W]: the wave's mean over the step."""
        self._inputs.set((demand,))
        self.fmu.step(time_s, step_size)
        return self._outputs.get()[0]

    def close(self):
        """Free the instance."""
        self.fmu.close()


def needed_fmus(scenario):
    """Names of the FMUs the FMU path of ``scenario`` runs: the plant, and the compensator
    and the PWM driver when the scenario has them."""
    return (["SmaActuator"] + (["SmaFeedforward"] if scenario.controller.feedforward else [])
            + (["SmaPwmDriver"] if scenario.drive.pwm else []))


def run_fmus(scenario, fmu_dir=DEFAULT_FMU_DIR):
    """Run ``scenario`` through the FMUs in ``fmu_dir``; returns a :class:`LoopResult`."""
    paths = default_fmu_paths(fmu_dir)
    for name in needed_fmus(scenario):
        if not paths[name].is_file():
            raise MissingFmuError(f"{paths[name]} not found; build the FMUs first: "
                                  f"sma-fmu build --out {Path(fmu_dir)}")
    start = time.perf_counter()
    parts = {}
    try:
        parts["plant"] = FmuPlant(scenario, paths["SmaActuator"])
        if scenario.controller.feedforward:
            parts["compensator"] = FmuCompensator(scenario, paths["SmaFeedforward"])
        if scenario.drive.pwm:
            parts["driver"] = FmuDriver(scenario, paths["SmaPwmDriver"])
        data = run_loop(scenario, parts["plant"], parts.get("compensator"),
                        driver=parts.get("driver"))
    except FmuError as error:
        raise FmuError(f"scenario {scenario.name}: {error}", error.status) from None
    finally:
        for part in parts.values():
            part.close()
    return LoopResult(scenario, data, "fmu", time.perf_counter() - start)
