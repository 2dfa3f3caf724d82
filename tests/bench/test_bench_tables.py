"""`sma-fmu bench --only hosts` and `--only pwm` (the former benchmarks/ scripts): they run
and say what they measured. No timing is asserted; the PWM cell is checked against physics."""
import json

from sma_fmu.bench.pwm_table import PWM_LOAD_KG, pwm_cell
from sma_fmu.cli import main
from sma_fmu.runtime.plant import PlantStepper


def test_host_table_runs_a_short_scenario_in_every_host(tmp_path, capsys):
    assert main(["bench", "--only", "hosts", "--scenario", "load-step-pi", "--stop-time", "0.2",
                 "--out", str(tmp_path)]) == 0
    rows = json.loads((tmp_path / "hosts.json").read_text())
    runs = {row["run"] for row in rows}
    assert {"libcosim", "ecos", "fmpy", "libcosim-container"} <= {r.split()[0] for r in runs} | runs
    out = capsys.readouterr().out
    assert "load-step-pi" in out and "libcosim" in out


def test_a_pwm_cell_at_a_fast_rate_holds_the_constant_power_resistance(params):
    """Continuous mode: 500 Hz PWM at the same mean power holds R within 0.1 ohm of constant
    power (return-point memory, docs/model.md section 6); switch mode chatters."""
    constant = pwm_cell(params, "continuous", 68.0, None, seconds=20.0)
    fast = pwm_cell(params, "continuous", 68.0, 500.0, seconds=20.0)
    chatter = pwm_cell(params, "switch", 68.0, 500.0, seconds=20.0)
    assert abs(fast[0] - constant[0]) < 0.1 and fast[1] - fast[0] < 0.1
    assert chatter[1] - chatter[0] > 1.0
    # the constant cell is the plant's steady state at that power
    plant = PlantStepper(params, mode="continuous", load=PWM_LOAD_KG)
    power = (68.0 - params.T_room) / params.K_th
    for _ in range(20000):
        out = plant.step(power, PWM_LOAD_KG, 1e-3)
    assert out.R == constant[0]  # still heating: R falls to the end of the window
