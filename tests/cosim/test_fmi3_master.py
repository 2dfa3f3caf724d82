"""The fmpy master (``sma-fmu run --fmus DIR``) over FMI 3.0 FMUs.

- Without events: the FMI 3.0 FMUs give the rows and metrics of their FMI 2.0 C-family twins
  to the bit, for the paper's six scenarios and both PWM ones; a folder mixing the versions
  runs too (each FMU through the adapter of its own version).
- With events (``--events``): the plant steps from edge to edge of the PWM wave. The plant's
  mean input power per PWM period [W] against the duty-cycle value (duty x peak power) is
  measured for the event-mode run and the fixed-step FMI 2.0 run (printed with ``-s``).
"""
import dataclasses
import json
import shutil

import numpy as np
import pytest

from cli_failure import fails
from sma_fmu.cli import main
from sma_fmu.cosim.event_drive import period_power_errors
from sma_fmu.cosim.master import run_fmus
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.scenario import PAPER_SET, load_scenario, resolve_scenarios
from sma_fmu.fmi.driving.instance import FmuError, FmuInstance
from sma_fmu.fmi.driving.instance3 import Fmu3Instance, open_instance
from test_c_master import DISCARD, PWM, _same

pytestmark = pytest.mark.needs("gcc")


def _scenario(name):
    return load_scenario(resolve_scenarios([name])[0])


@pytest.fixture(scope="module")
def fmi2_dir(native_fmus):
    return native_fmus["SmaActuator"].parent


@pytest.fixture(scope="module")
def fmi3_dir(fmi3_fmus):
    return fmi3_fmus["SmaActuator"].parent


def test_each_fmu_gets_the_adapter_of_its_version(fmi2_dir, fmi3_dir):
    with open_instance(fmi3_dir / "SmaActuator.fmu", "v3", {"hysteresis_mode": 2}) as three:
        assert type(three) is Fmu3Instance and three.variables["hysteresis_mode"].type == "Enumeration"
        three.step(0.0, 1e-3)
        assert three.get_real(("T",))[0] > 0.0
    with open_instance(fmi2_dir / "SmaActuator.fmu", "v2") as two:
        assert type(two) is FmuInstance
    with pytest.raises(ValueError, match=r"SmaActuator\.fmu is an FMI 2\.0 FMU: event mode"):
        open_instance(fmi2_dir / "SmaActuator.fmu", "v2", events=True)


def test_saved_states_replay_through_the_fmi3_adapter(fmi3_dir):
    with open_instance(fmi3_dir / "SmaActuator.fmu", "states", {"load": 0.1}) as fmu:
        def run(first):
            values = []
            for k in range(first, first + 50):
                fmu.set_real(("P_in",), (0.3 + 0.2 * (k % 7),))
                fmu.step(k * 1e-3, 1e-3)
                values.append(fmu.get_real(("R", "T")))
            return values
        run(0)
        saved = fmu.get_state()
        state = fmu.deserialize_state(fmu.serialize_state(saved))
        fmu.free_state(saved)
        first = run(50)
        fmu.set_state(state)
        fmu.free_state(state)
        assert run(50) == first and first[0] != first[-1]


def test_a_block_that_returns_early_unasked_is_an_error(fmi3_dir):
    """The master's fixed-grid step (LeanStep) of a block in event mode: an early return
    it does not handle is an FmuError naming fmi3DoStep, not a silently short step."""
    from sma_fmu.cosim.master import LeanStep
    with open_instance(fmi3_dir / "SmaPwmDriver.fmu", "early", {"frequency_Hz": 130.0},
                       events=True) as fmu:
        lean = LeanStep(fmu, ("P_demand",), ("P_in",))
        lean.inputs[0] = 0.3 * fmu.get_real(("peak_W",))[0]
        with pytest.raises(FmuError, match=r"early: fmi3DoStep failed \(error\): returned early"):
            for k in range(10):
                lean.step(k * 1e-3, 1e-3)


@pytest.mark.parametrize("name", PAPER_SET + PWM)
def test_fmi3_fmus_give_the_fmi2_rows_and_metrics_to_the_bit(fmi2_dir, fmi3_dir, name):
    scenario = _scenario(name)
    two, three = run_fmus(scenario, fmi2_dir), run_fmus(scenario, fmi3_dir)
    assert len(three.data) == scenario.steps + 1
    _same(three.data, two.data)
    assert scenario_metrics(three.data, scenario) == scenario_metrics(two.data, scenario)
    assert np.ptp(three.data["R"]) > 1.0 and np.ptp(three.data["P"][:-1]) > 0.1  # the loop moved


def test_a_folder_mixing_versions_runs_each_through_its_own(fmi2_dir, fmi3_dir, tmp_path, capsys):
    for path in fmi2_dir.glob("*.fmu"):
        shutil.copy(path, tmp_path)
    for name in ("SmaActuator", "SmaPwmDriver"):
        shutil.copy(fmi3_dir / f"{name}.fmu", tmp_path)
    scenario = _scenario(PWM[0])
    _same(run_fmus(scenario, tmp_path).data, run_fmus(scenario, fmi2_dir).data)
    fails(capsys, ["run", PWM[0], "--fmus", str(tmp_path), "--events", "--out",
                   str(tmp_path / "out")], "--events", "SmaFeedforward.fmu is an FMI 2.0 FMU")
    assert not (tmp_path / "out").exists()


def test_a_discard_names_the_fmi3_function_and_quotes_the_log(fmi3_dir, tmp_path):
    (tmp_path / "discard.toml").write_text(DISCARD.format(stop=1.0))
    with pytest.raises(FmuError) as caught:
        run_fmus(load_scenario(tmp_path / "discard.toml"), fmi3_dir)
    text = str(caught.value)
    assert "plant: fmi3DoStep failed (discard)" in text and "fmi2" not in text
    assert "t = 0.5 s discarded" in text and "floating-point range" in text


def test_event_mode_without_pwm_changes_nothing(fmi3_dir):
    """Plant and compensator in event mode (no events of their own): the fixed-step rows."""
    scenario = _scenario("load-step-pi+ff-adaptive")
    _same(run_fmus(scenario, fmi3_dir, events=True).data, run_fmus(scenario, fmi3_dir).data)


def _at(scenario, frequency_Hz):
    return dataclasses.replace(scenario, drive=dataclasses.replace(scenario.drive,
                                                                   frequency_Hz=frequency_Hz))


def _runs(scenario, fmi2_dir, fmi3_dir):
    """(fixed-step FMI 2.0, event-mode FMI 3.0): each (result, power trace)."""
    fixed, events = [], []
    return ((run_fmus(scenario, fmi2_dir, power_trace=fixed), fixed),
            (run_fmus(scenario, fmi3_dir, events=True, power_trace=events), events))


def test_event_mode_keeps_the_row_grid_and_the_energy_per_step(fmi2_dir, fmi3_dir):
    """Rows on the fixed grid; each row's P is the plant's energy over its step / h [W]."""
    scenario = _scenario(PWM[0])
    (fixed, fixed_trace), (events, trace) = _runs(scenario, fmi2_dir, fmi3_dir)
    assert len(events.data) == scenario.steps + 1
    assert np.array_equal(events.data["t"], fixed.data["t"])
    assert len(fixed_trace) == scenario.steps and len(trace) > scenario.steps + 500  # edges
    starts, ends, _, powers = (np.array(column) for column in zip(*trace))
    # the wave is on or off over each plant step: the peak or 0 W, but for slivers [J] of
    # rounding where a step of microseconds ends at an edge (the time's rounding at t ~ 30 s
    # times the peak: 1.4e-14 J)
    off = np.minimum(np.abs(powers), np.abs(powers - scenario.drive.peak_W))
    assert np.all(off * (ends - starts) < 1e-13)
    step = np.floor(starts / scenario.step_s + 1e-6).astype(int)
    energy = np.bincount(step, weights=powers * (ends - starts), minlength=scenario.steps)
    assert np.allclose(energy / scenario.step_s, events.data["P"][:-1], rtol=0, atol=1e-9)


def test_event_mode_gives_the_duty_cycle_power_per_period_more_closely(fmi2_dir, fmi3_dir):
    """The PWM scenario at 130 Hz (a period is no whole number of 1 ms steps): the plant's
    mean input power per period [W] equals the duty-cycle value closer with event mode and
    early return than in the fixed-step FMI 2.0 run. At the scenario's own 50 Hz (20 whole
    steps a period) both equal it to rounding."""
    found = {}
    for frequency_Hz in (130.0, 50.0):
        scenario = _at(_scenario(PWM[0]), frequency_Hz)
        runs = _runs(scenario, fmi2_dir, fmi3_dir)
        found[frequency_Hz] = [period_power_errors(trace, frequency_Hz, scenario.drive.peak_W,
                                                   scenario.stop_time_s) for _, trace in runs]
        for label, errors in zip(("FMI 2.0 fixed 1 ms steps", "FMI 3.0 event mode"),
                                 found[frequency_Hz]):
            print(f"{PWM[0]} at {frequency_Hz:g} Hz, {label}: |mean power per period - duty x "
                  f"peak| largest {errors.max():.3g} W, mean {errors.mean():.3g} W "
                  f"({len(errors)} periods)")
    fixed, events = found[130.0]
    assert events.max() < 1e-9 and fixed.max() > 0.01 and events.max() < fixed.max() / 1e6
    assert max(errors.max() for errors in found[50.0]) < 1e-9


def test_the_cli_runs_with_events_and_refuses_them_elsewhere(fmi3_dir, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", PWM[0], "--fmus", str(fmi3_dir), "--events", "--out", str(out)]) == 0
    metrics = json.loads((out / PWM[0] / "metrics.json").read_text())
    assert metrics["events"] is True and metrics["master"] == "fmpy"
    fails(capsys, ["run", PWM[0], "--fmus", str(fmi3_dir), "--events", "--master", "c",
                   "--out", str(tmp_path / "c")], "--events", "--master c")


def test_the_c_master_refuses_fmi3_fmus_by_name(fmi3_dir, tmp_path, capsys):
    """The C master is an FMI 2.0 host: FMI 3.0 FMUs get one line naming the FMU and the
    master that runs them, and the output folder is not made."""
    out = tmp_path / "c"
    fails(capsys, ["run", "load-step-pi", "--fmus", str(fmi3_dir), "--master", "c", "--out",
                   str(out)], "is an FMI 3.0 FMU", "--master fmpy", str(fmi3_dir))
    assert not out.exists()
