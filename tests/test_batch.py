"""The batch engine equals the scalar library path (<= 1e-10) on random sets of runs.

The sets (sma_fmu.studies.random_set, also the benchmark's) mix every controller in both
hysteresis modes with random gains, filters, loads, references, wire and model parameters.
"""
import itertools

import numpy as np
import pytest

import sma_fmu.studies.batch as batch
from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.scenario import CONTROLLERS
from sma_fmu.runtime.checks import HYSTERESIS_MODES
from sma_fmu.studies import BatchUnsupported, StudyError, run_batch, run_many, template
from sma_fmu.studies.random_set import random_scenarios

TOLERANCE = 1e-10   # ohm, degC, m, W, kg, 1: the bound on every column


def assert_same_series(batch_data, scalar_data, label):
    assert batch_data.dtype == scalar_data.dtype
    for field in scalar_data.dtype.names:
        if field == "saturated":
            assert np.array_equal(batch_data[field], scalar_data[field]), (label, field)
        else:
            np.testing.assert_allclose(batch_data[field], scalar_data[field], rtol=0,
                                       atol=TOLERANCE, equal_nan=True, err_msg=f"{label} {field}")


@pytest.mark.parametrize("seed, chunk", [(1, None), (2, 64)])
def test_random_sets_equal_the_library_path(seed, chunk, monkeypatch):
    if chunk:   # tiny chunks: load steps inside chunks, many chunk boundaries
        monkeypatch.setattr(batch, "CHUNK_ELEMENTS", chunk)
    scenarios = random_scenarios(12, seed)
    results = run_batch(scenarios, "timeseries")
    kinds = {(s.controller.kind, s.hysteresis_mode) for s in scenarios}
    assert kinds == set(itertools.product(CONTROLLERS, HYSTERESIS_MODES))
    for scenario, result in zip(scenarios, results):
        assert result.path == "batch" and result.error is None
        scalar = run_library(scenario).data
        assert_same_series(result.data, scalar, f"{scenario.controller.kind} {scenario.hysteresis_mode}")
        assert result.metrics == scenario_metrics(scalar, scenario)


def test_streamed_metrics_equal_scenario_metrics(monkeypatch):
    monkeypatch.setattr(batch, "CHUNK_ELEMENTS", 200)
    scenarios = random_scenarios(8, 3)
    streamed = run_batch(scenarios, "metrics")
    for scenario, result in zip(scenarios, streamed):
        assert result.data is None
        expected = scenario_metrics(run_library(scenario).data, scenario)
        assert result.metrics.keys() == expected.keys()
        for key in ("scenario", "controller", "hysteresis_mode", "window"):
            assert result.metrics[key] == expected[key]
        for part, reference in zip(
                [result.metrics["overall"], result.metrics["reachable"]] + result.metrics["segments"],
                [expected["overall"], expected["reachable"]] + expected["segments"]):
            assert part.keys() == reference.keys()
            for key, value in reference.items():
                if value is None:                       # a segment before the window
                    assert part[key] is None
                else:
                    assert part[key] == pytest.approx(value, rel=1e-12, abs=1e-15), key
        for key in ("saturated_fraction", "clamped_fraction", "unreachable_fraction"):
            assert result.metrics[key] == pytest.approx(expected[key], rel=1e-12)
        for key in ("unreachable_intervals_s", "warnings", "inverse", "metrics_start_s"):
            assert result.metrics[key] == expected[key], key


def test_a_run_that_fails_in_the_batch_gets_the_scalar_paths_error():
    base = template("load-step-pi+ff-adaptive")
    good = base.scenario({"scenario.stop_time_s": 3.0})
    broken = base.scenario({"scenario.stop_time_s": 3.0,   # dH(f)/k_B of 10 K: no inverse
                            "model.eps_T": 1e-30})
    with pytest.raises(ValueError) as scalar_error:
        run_library(broken)
    first, second = run_batch([good, broken])
    assert first.error is None and first.path == "batch"
    assert second.metrics is None and second.path == "library"
    assert second.error == str(scalar_error.value) and "inverse diverges" in second.error


def test_options_the_engine_lacks_are_refused_never_computed_differently():
    base = template("load-step-pi+ff-adaptive")
    scenario = base.scenario({"scenario.stop_time_s": 3.0})
    minor = base.scenario({"scenario.stop_time_s": 3.0, "controller.inverse": "minor-loop"})
    assert batch.unsupported_reason(scenario) is None    # inverse = "major", the default
    assert "inverse = 'minor-loop'" in batch.unsupported_reason(minor)
    with pytest.raises(BatchUnsupported, match="minor-loop"):
        run_batch([scenario, minor])
    with pytest.raises(StudyError, match="path='library'"):
        run_many([minor], path="batch")


def test_runs_must_share_step_and_duration():
    base = template("load-step-pi")
    with pytest.raises(ValueError, match="one step and duration"):
        run_batch([base.scenario({"scenario.stop_time_s": 3.0}),
                   base.scenario({"scenario.stop_time_s": 4.0})])
