"""The shaped compensator (shaping "reachable") in the closed loop: its scenarios, the key's
refusals, and the library path, the fmpy master over both FMU families and the C master
giving the same run."""
import dataclasses

import numpy as np
import pytest
from numpy.lib.recfunctions import structured_to_unstructured

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.master import run_fmus
from sma_fmu.cosim.scenario import ScenarioError, load_scenario, scenario_names
from sma_fmu.files.package_data import shipped_file
from sma_fmu.systems.c_master import run_c_master
from system_needs import needs

SHAPED = [f"{profile}{mode}-pi+ff-adaptive-reachable" for profile in ("load-step", "heavy")
          for mode in ("", "-continuous")]


def _scenario(name, **changes):
    return dataclasses.replace(load_scenario(shipped_file("scenarios", f"{name}.toml")),
                               **changes)


def _close(a, b):
    assert a.dtype == b.dtype and np.array_equal(a["saturated"], b["saturated"])
    reals = [name for name in a.dtype.names if name != "saturated"]
    np.testing.assert_allclose(structured_to_unstructured(a[reals]),
                               structured_to_unstructured(b[reals]), rtol=0, atol=1e-9,
                               equal_nan=True)


def test_the_shaped_scenarios_ship_beside_their_twins():
    assert set(SHAPED) <= set(scenario_names())
    for name in SHAPED:
        scenario, twin = _scenario(name), _scenario(name.replace("-reachable", ""))
        assert scenario.controller.shaping == "reachable" and twin.controller.shaping == "none"
        assert scenario.controller.inverse == ("minor-loop" if "continuous" in name else "major")
        assert (scenario.reference.settings, scenario.load.as_table(), scenario.hysteresis_mode,
                scenario.stop_time_s) == (twin.reference.settings, twin.load.as_table(),
                                          twin.hysteresis_mode, twin.stop_time_s)


@pytest.mark.parametrize("change,message", [
    (lambda s: s.replace('shaping = "reachable"', 'shaping = "reach"'),
     r"\[controller\] shaping must be one of none, reachable, got 'reach'"),
    (lambda s: s.replace('kind = "pi+ff-adaptive"', 'kind = "pi"'),
     r"\[controller\] inverse|\[controller\] shaping = 'reachable' needs a feedforward"),
    (lambda s: s.replace('shaping = "reachable"', 'power_cap_W = 5.0'),
     r"\[controller\] power_cap_W = 5.0 needs shaping = 'reachable', got 'none'"),
    (lambda s: s.replace('shaping = "reachable"', 'shaping = "reachable"\npower_cap_W = -1.0'),
     r"power_cap_W"),
    (lambda s: s.replace('shaping = "reachable"', 'anticipation_s = 0.2'),
     r"\[controller\] anticipation_s = 0.2 needs shaping = 'reachable', got 'none'"),
    (lambda s: s.replace('shaping = "reachable"', 'shaping = "reachable"\nanticipation_s = -0.1'),
     r"\[controller\] anticipation_s must be >= 0, got -0.1"),
])
def test_bad_shaping_keys_name_file_and_value(tmp_path, change, message):
    path = tmp_path / "custom.toml"
    path.write_text(change(shipped_file("scenarios", "heavy-pi+ff-adaptive-reachable.toml")
                           .read_text()))
    with pytest.raises(ScenarioError, match=message) as raised:
        load_scenario(path)
    assert str(path) in str(raised.value)


def _capped(name):
    scenario = _scenario(name, stop_time_s=3.0)
    return dataclasses.replace(scenario, controller=dataclasses.replace(
        scenario.controller, power_cap_W=3.0))


@needs("gcc")
@pytest.mark.parametrize("name", ["load-step-pi+ff-adaptive-reachable",
                                  "heavy-continuous-pi+ff-adaptive-reachable"])
def test_both_fmu_families_and_the_c_master_run_the_library_loop(fmus, native_dir, name):
    scenario = _capped(name)
    library = run_library(scenario).data
    _close(run_fmus(scenario, fmus["SmaActuator"].parent).data, library)
    _close(run_fmus(scenario, native_dir).data, library)
    _close(run_c_master(scenario, native_dir).data, library)
    unshaped = run_library(dataclasses.replace(scenario, controller=dataclasses.replace(
        scenario.controller, shaping="none", power_cap_W=None))).data
    assert np.max(np.abs(unshaped["P_ff"][:-1] - library["P_ff"][:-1])) > 0.1   # not the paper's
    assert np.max(library["P_ff"][:-1]) <= 3.0                           # the cap holds


BENCH = [f"{profile}{mode}-bench-pi+ff-adaptive-reachable" for profile in ("load-step", "heavy")
         for mode in ("", "-continuous")]


def test_the_bench_scenarios_of_the_shaped_compensator_ship_with_the_bench_and_its_limit():
    """Their twins' reference, loads, mode, sensor and driver; the compensator's P_max is
    no more than the driver's current limit gives at the lowest R the reference asks for."""
    assert set(BENCH) <= set(scenario_names())
    for name in BENCH:
        scenario, twin = _scenario(name), _scenario(name.replace("-reachable", ""))
        c = scenario.controller
        assert (c.shaping, c.inverse) == ("reachable",
                                          "minor-loop" if "continuous" in name else "major")
        assert c.anticipation_s > 0 and twin.controller.shaping == "none"
        assert (scenario.reference.settings, scenario.load.as_table(), scenario.hysteresis_mode,
                scenario.sensor, scenario.drive) == (twin.reference.settings,
                                                     twin.load.as_table(), twin.hysteresis_mode,
                                                     twin.sensor, twin.drive)
        lowest = twin.reference.settings["offset_ohm"] - twin.reference.settings["amplitude_ohm"]
        assert c.power_cap_W <= scenario.drive.I_max_A ** 2 * lowest


@needs("gcc")
@pytest.mark.parametrize("name", ["load-step-bench-pi+ff-adaptive-reachable",
                                  "heavy-continuous-bench-pi+ff-adaptive-reachable"])
def test_the_anticipating_compensator_runs_alike_in_every_path(fmus, native_dir, name):
    """3 s hold the reference's first lower turn (t = 1 s), where the anticipation acts."""
    scenario = _scenario(name, stop_time_s=3.0)
    library = run_library(scenario).data
    _close(run_fmus(scenario, fmus["SmaActuator"].parent).data, library)
    _close(run_fmus(scenario, native_dir).data, library)
    _close(run_c_master(scenario, native_dir).data, library)
    plain = run_library(dataclasses.replace(scenario, controller=dataclasses.replace(
        scenario.controller, anticipation_s=0.0))).data
    assert np.max(np.abs(plain["P_ff"][:-1] - library["P_ff"][:-1])) > 0.1
