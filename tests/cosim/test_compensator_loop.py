"""The minor-loop compensator in the closed loop (FMU and library paths), scenarios and reachability."""
import json
import math

import numpy as np
import pytest
from numpy.lib.recfunctions import structured_to_unstructured

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.master import run_fmus
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.systems.runner import run_scenarios
from sma_fmu.cosim.scenario import ScenarioError, load_scenario, scenario_names
from sma_fmu.fmi.driving.instance import FmuInstance
from sma_fmu.files.package_data import shipped_file

MINOR_LOOP = [f"{profile}{mode}-pi+ff-adaptive-minor-loop" for profile in ("load-step", "heavy")
              for mode in ("", "-continuous")]


def _scenario(name):
    return load_scenario(shipped_file("scenarios", f"{name}.toml"))


def _variant(tmp_path, name, change, stem="custom"):
    path = tmp_path / f"{stem}.toml"
    path.write_text(change(shipped_file("scenarios", f"{name}.toml").read_text()))
    return path


def test_minor_loop_scenarios_ship_with_the_paper_inverse_as_default():
    assert set(MINOR_LOOP) <= set(scenario_names())
    for name in MINOR_LOOP:
        scenario = _scenario(name)
        assert scenario.controller.kind == "pi+ff-adaptive"
        assert scenario.controller.inverse == "minor-loop"
        assert scenario.hysteresis_mode == ("continuous" if "continuous" in name else "switch")
    for name in ("load-step-pi+ff-adaptive", "heavy-continuous-pi+ff-fixed"):
        assert _scenario(name).controller.inverse == "major"


@pytest.mark.parametrize("change,message", [
    (lambda s: s.replace('inverse = "minor-loop"', 'inverse = "minor"'),
     r"\[controller\] inverse must be one of major, minor-loop, got 'minor'"),
    (lambda s: s.replace('kind = "pi+ff-adaptive"', 'kind = "pi"'),
     r"\[controller\] inverse = 'minor-loop' needs a feedforward controller .*got kind 'pi'"),
])
def test_bad_inverse_key_names_file_and_value(tmp_path, change, message):
    path = _variant(tmp_path, "load-step-continuous-pi+ff-adaptive-minor-loop", change)
    with pytest.raises(ScenarioError, match=message) as raised:
        load_scenario(path)
    assert str(path) in str(raised.value)


def test_minor_loop_controller_fmu_path_equals_library_path(fmus):
    name = "load-step-continuous-pi+ff-adaptive-minor-loop"
    scenario = _scenario(name)
    library = run_library(scenario).data
    fmu = run_fmus(scenario, fmus["SmaActuator"].parent).data
    assert fmu.dtype == library.dtype and np.array_equal(fmu["saturated"], library["saturated"])
    reals = [name for name in library.dtype.names if name != "saturated"]
    np.testing.assert_allclose(structured_to_unstructured(fmu[reals]),
                               structured_to_unstructured(library[reals]),
                               rtol=0, atol=1e-9, equal_nan=True)
    major = run_library(_scenario(name.replace("-minor-loop", ""))).data
    assert np.max(np.abs(major["T_ref"][:-1] - library["T_ref"][:-1])) > 1.0  # another inverse


def test_minor_loop_option_reaches_the_system_tools(fmus, tmp_path):
    """The SSP binds inverse = minor-loop, and a host run matches the library loop."""
    import dataclasses
    import xml.etree.ElementTree as ET
    import zipfile

    from sma_fmu.systems.closed_loop import closed_loop
    from sma_fmu.systems.comparison import compare_hosts
    from sma_fmu.systems.ssp import NAMESPACES, SSD_NAME, write_ssp

    scenario = dataclasses.replace(_scenario("load-step-continuous-pi+ff-adaptive-minor-loop"),
                                   stop_time_s=2.2)
    fmu_dir = fmus["SmaActuator"].parent
    path = write_ssp(closed_loop(scenario, fmu_dir), tmp_path / "minor.ssp")
    with zipfile.ZipFile(path) as archive:
        root = ET.fromstring(archive.read(SSD_NAME))
    bound = {(c.get("name"), p.get("name")): p[0].get("value")
             for c in root.iter(f"{{{NAMESPACES['ssd']}}}Component")
             for p in c.iter(f"{{{NAMESPACES['ssv']}}}Parameter")}
    assert bound[("compensator", "inverse")] == "2"  # the Integer code of minor-loop
    rows = compare_hosts(scenario, fmu_dir, hosts=("fmpy",))
    assert rows[-1]["run"] == "fmpy (container)" and rows[-1]["deviation"] <= 1e-9


def test_feedforward_fmu_state_keeps_the_minor_loop_memory(fmus):
    start = {"inverse": 2, "R_ref": 45.0, "load": 0.05}  # 2 = minor-loop
    references = [41.85 + 6.05 * math.cos(math.pi * k * 1e-3) for k in range(3000)]
    with FmuInstance(fmus["SmaFeedforward"], "ff-minor", start) as fmu:
        ports = fmu.port(("R_ref", "load")), fmu.port(("P_ff", "T_ref"))

        def run(first, last):
            trace = []
            for k in range(first, last):
                ports[0].set((references[k], 0.05))
                fmu.step(k * 1e-3, 1e-3)
                trace.append(tuple(ports[1].get()))
            return trace

        run(0, 1500)  # past the reversal at t = 1 s
        state = fmu.get_state()
        first = run(1500, 3000)
        fmu.set_state(state)
        assert run(1500, 3000) == first
        fmu.free_state(state)


def _wide(tmp_path):
    """load-step with R_ref = 41 + 9 cos(pi t): leaves the band at both ends."""
    return _variant(tmp_path, "load-step-continuous-pi+ff-adaptive-minor-loop",
                    lambda s: s.replace("offset_ohm = 41.85", "offset_ohm = 41.0")
                    .replace("amplitude_ohm = 6.05", "amplitude_ohm = 9.0"), stem="wide")


def test_metrics_report_the_unreachable_part_of_the_run(tmp_path, params):
    scenario = load_scenario(_wide(tmp_path))
    data = run_library(scenario).data
    metrics = scenario_metrics(data, scenario)
    # the band from the spec's formulas (section 4), independently of the runtime
    residual = params.xi_F_inf * (1.0 - np.exp(-data["load"] / params.f_F))
    hot = params.R_P + residual * (params.R_F - params.R_P)
    cold = hot + (1.0 - residual) * (0.5 * (params.R_M + params.R_F) - params.R_P)
    outside = (data["R_ref"] <= hot) | (data["R_ref"] >= cold)
    window = data["t"] >= 2.0 - 1e-12
    assert metrics["unreachable_fraction"] == pytest.approx(np.mean(outside[window]), abs=1e-12)
    assert 0.2 < metrics["unreachable_fraction"] < 0.4
    error = (data["R"] - data["R_ref"])[window & ~outside]
    assert metrics["reachable"]["rmse_ohm"] == pytest.approx(np.sqrt(np.mean(error ** 2)), rel=1e-12)
    assert metrics["reachable"]["samples"] == int(np.sum(window & ~outside))
    intervals = metrics["unreachable_intervals_s"]
    # the compensator clamps there, and where its minor branch reaches less than the band:
    # the first sample back inside, after a reversal at the band's edge
    saturated, controlled = data["saturated"][:-1], outside[:-1]  # the last row has no control
    assert np.all(saturated[controlled])
    extra = np.flatnonzero(saturated & ~controlled)
    assert 0 < len(extra) <= len(intervals) and np.all(controlled[extra - 1])
    assert intervals[0] == [0.0, pytest.approx(0.106, abs=1e-3), "above R_cold"]
    assert intervals[1][2] == "below R_hot" and intervals[1][0] == pytest.approx(0.847, abs=1e-3)
    assert sum(b - a + 1e-3 for a, b, _ in intervals) == pytest.approx(1e-3 * outside.sum(), abs=1e-9)
    assert len(metrics["warnings"]) == 1 and f"{len(intervals)} interval(s)" in metrics["warnings"][0]


def test_runner_warns_once_per_run_in_the_log_and_metrics(tmp_path):
    wide = _wide(tmp_path)
    short = tmp_path / "short-wide.toml"
    short.write_text(wide.read_text().replace("stop_time_s = 30.0", "stop_time_s = 5.0"))
    messages = []
    run_scenarios([short], tmp_path / "out", path="library", progress=messages.append)
    warnings = [m for m in messages if m.startswith("warning:")]
    assert len(warnings) == 1
    assert warnings[0].startswith("warning: short-wide: R_ref leaves the band the wire can reach")
    assert "interval(s) between t = 0 s and 5 s" in warnings[0]
    assert "0.847-1.153 s (below R_hot)" in warnings[0] and "and 2 more" in warnings[0]
    written = json.loads((tmp_path / "out" / "short-wide" / "metrics.json").read_text())
    assert written["warnings"] == [warnings[0][len("warning: short-wide: "):]]


def test_paper_reference_stays_reachable():
    scenario = _scenario("load-step-continuous-pi+ff-adaptive-minor-loop")
    metrics = scenario_metrics(run_library(scenario).data, scenario)
    assert metrics["unreachable_fraction"] == 0.0 and metrics["warnings"] == []
    assert metrics["unreachable_intervals_s"] == [] and metrics["saturated_fraction"] == 0.0
    assert metrics["reachable"] == metrics["overall"] and metrics["inverse"] == "minor-loop"
