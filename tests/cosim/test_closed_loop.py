"""The closed loop: the paper's finding, FMU path = library path, sequencing and the clamp."""
import numpy as np
import pytest

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.master import run_fmus
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.files.package_data import shipped_file
from sma_fmu.cosim.scenario import CONTROLLERS, load_scenario


def _scenario(name):
    return load_scenario(shipped_file("scenarios", f"{name}.toml"))


@pytest.fixture(scope="module")
def rmse():
    """RMSE [ohm] (t >= 2 s) of every shipped scenario, library path."""
    values = {}
    for group in ("load-step", "heavy", "load-step-continuous", "heavy-continuous"):
        for controller in CONTROLLERS:
            scenario = _scenario(f"{group}-{controller}")
            result = run_library(scenario)
            values[group, controller] = scenario_metrics(result.data, scenario)["overall"]["rmse_ohm"]
    return values


@pytest.mark.parametrize("group", ["load-step", "heavy"])
def test_paper_finding_controller_ordering(rmse, group):
    assert rmse[group, "pi"] > rmse[group, "pi+ff-fixed"] > rmse[group, "pi+ff-adaptive"]


def test_paper_finding_fixed_vs_adaptive_gap_largest_at_heavy_load(rmse):
    gap = {g: rmse[g, "pi+ff-fixed"] - rmse[g, "pi+ff-adaptive"] for g in ("load-step", "heavy")}
    assert gap["heavy"] > gap["load-step"] > 0.0


@pytest.mark.parametrize("group", ["load-step-continuous", "heavy-continuous"])
def test_ordering_also_holds_with_continuous_minor_loops(rmse, group):
    assert rmse[group, "pi"] > rmse[group, "pi+ff-fixed"] > rmse[group, "pi+ff-adaptive"]


@pytest.mark.parametrize("name", ["load-step-pi+ff-adaptive", "heavy-continuous-pi+ff-fixed",
                                  "load-step-pi"])
def test_fmu_path_equals_library_path(fmus, name):
    scenario = _scenario(name)
    library = run_library(scenario).data
    fmu = run_fmus(scenario, fmus["SmaActuator"].parent).data
    assert library.dtype == fmu.dtype and len(library) == scenario.steps + 1
    for field in library.dtype.names:
        if field == "saturated":
            assert np.array_equal(library[field], fmu[field])
        else:
            np.testing.assert_allclose(fmu[field], library[field], rtol=0, atol=1e-9,
                                       equal_nan=True, err_msg=field)


def test_loop_sequencing_and_power_clamp(params):
    scenario = _scenario("heavy-pi+ff-adaptive")
    data = run_library(scenario).data
    first = data[0]
    # step 0 uses R_0 (the plant after initialization) and the PI with I_0 = 0
    assert first["P_fb"] == pytest.approx(params.Kp * (first["R"] - first["R_ref"]), abs=1e-15)
    assert first["P"] == pytest.approx(first["P_ff"] + first["P_fb"], abs=1e-15)
    assert first["P_ff"] == pytest.approx((first["T_ref"] - params.T_room) / params.K_th, abs=1e-12)
    power = data["P"][:-1]
    raw = data["P_ff"][:-1] + data["P_fb"][:-1]
    assert power.min() == 0.0 and (raw < 0).any()            # the clamp acted
    np.testing.assert_array_equal(power, np.maximum(0.0, raw))
    assert np.isnan(data[-1]["P"]) and np.isfinite(data[-1]["R"])  # sample n: outputs only


def test_metrics_windows_and_segments():
    scenario = _scenario("load-step-pi")
    metrics = scenario_metrics(run_library(scenario).data, scenario)
    assert metrics["overall"]["samples"] == 28001                 # k = 2000 ... 30000
    assert [s["samples"] for s in metrics["segments"]] == [8000, 10000, 10001]
    assert [s["load_kg"] for s in metrics["segments"]] == [0.0032, 0.05, 0.15]
    data = run_library(scenario).data
    error = (data["R"] - data["R_ref"])[2000:]
    assert metrics["overall"]["iae_ohm_s"] == pytest.approx(1e-3 * np.abs(error).sum(), rel=1e-12)
    assert metrics["overall"]["rmse_ohm"] == pytest.approx(np.sqrt(np.mean(error ** 2)), rel=1e-12)
