"""Stroke scenarios in the batch engine: two scenarios with the same stroke reference at other
loads map it to other R_ref (no shared reference column), each the library path's."""
import dataclasses

import numpy as np
import pytest

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios
from sma_fmu.files.package_data import shipped_file
from sma_fmu.studies.batch import run_batch

SCENARIO = """
[scenario]
model = "{model}"
stop_time_s = 1.0
step_s = 0.005

[reference]
quantity = "stroke"
kind = "cosine"
offset_mm = 8.0
amplitude_mm = 3.0
frequency_hz = 1.0

[load]
times_s = [0.0]
values_kg = [{load}]

[controller]
kind = "pi+ff-adaptive"
"""


def test_same_stroke_other_loads_get_their_own_r_ref(tmp_path):
    scenarios = []
    for load in (0.05, 0.15):
        path = tmp_path / f"stroke-{load}.toml"
        path.write_text(SCENARIO.format(model=shipped_file("models", "reference_wire.toml"),
                                        load=load))
        scenarios.append(load_scenario(path))
    runs = run_batch(scenarios, record="timeseries")
    references = []
    for scenario, run in zip(scenarios, runs):
        library = run_library(scenario).data
        assert np.array_equal(run.data["R_ref"], library["R_ref"])
        assert np.allclose(run.data["R"], library["R"], rtol=0.0, atol=1e-9)
        references.append(library["R_ref"])
    assert not np.allclose(references[0], references[1])


def test_the_metrics_record_has_the_library_stroke_record(tmp_path):
    """Without time series (a sweep's and a tuning's batch), a stroke run's ``stroke`` record is
    the one the library path's series gives; a resistance run beside it has none."""
    path = tmp_path / "stroke.toml"
    path.write_text(SCENARIO.format(model=shipped_file("models", "reference_wire.toml"), load=0.1)
                    .replace("times_s = [0.0]", "times_s = [0.0, 0.5]")
                    .replace("values_kg = [0.1]", "values_kg = [0.1, 0.15]")
                    .replace("stop_time_s = 1.0", "stop_time_s = 3.0"))
    stroke = load_scenario(path)
    other = dataclasses.replace(stroke, controller=dataclasses.replace(stroke.controller, Kp=1.0))
    plain = resolve_scenarios(["load-step-pi"])[0]
    plain = load_scenario(plain)
    plain = dataclasses.replace(plain, stop_time_s=stroke.stop_time_s, step_s=stroke.step_s)
    runs = run_batch([stroke, plain, other])
    assert "stroke" not in runs[1].metrics
    for scenario, run in zip((stroke, other), (runs[0], runs[2])):
        library = scenario_metrics(run_library(scenario).data, scenario)["stroke"]
        batch = run.metrics["stroke"]
        assert batch["samples"] == library["samples"] > 0
        for key in ("rmse_um", "max_abs_um", "iae_um_s"):
            assert batch[key] == pytest.approx(library[key], rel=1e-9)
        assert batch["segments_rmse_um"] == pytest.approx(library["segments_rmse_um"], rel=1e-9)
    assert runs[0].metrics["stroke"]["rmse_um"] != runs[2].metrics["stroke"]["rmse_um"]
