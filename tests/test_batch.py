"""The batch engine equals the scalar library path (<= 1e-10) on random sets of runs.

The sets (sma_fmu.studies.random_set, also the benchmark's) mix every controller (both
inverses, with the fixed and the adaptive compensator) in both hysteresis modes with random
gains, filters, loads, references, wire and model parameters; some runs get a random
piecewise-linear reference, so the compensators reverse at different samples, on plateaus
and outside the band the wire can reach.
"""
import dataclasses
import itertools

import numpy as np
import pytest

import sma_fmu.runtime.sensing as sensing
import sma_fmu.studies.batch as batch
from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.runtime.checks import HYSTERESIS_MODES
from sma_fmu.runtime.signals import ReferenceSignal
from sma_fmu.studies import BatchUnsupported, StudyError, run_batch, run_many, template
from sma_fmu.studies.random_set import ALL_CONTROLLERS, gain_grid_scenarios, random_scenarios

TOLERANCE = 1e-10   # ohm, degC, m, W, kg, 1: the bound on every column


def assert_same_series(batch_data, scalar_data, label):
    assert batch_data.dtype == scalar_data.dtype
    for field in scalar_data.dtype.names:
        if field == "saturated":
            assert np.array_equal(batch_data[field], scalar_data[field]), (label, field)
        else:
            np.testing.assert_allclose(batch_data[field], scalar_data[field], rtol=0,
                                       atol=TOLERANCE, equal_nan=True, err_msg=f"{label} {field}")


def random_walk_reference(rng, stop_time_s):
    """R_ref through random points every 0.05-0.4 s, 30-52 ohm (beyond the band's ends),
    with plateaus (equal neighbours: d_ref keeps its direction)."""
    times, values = [0.0], [rng.uniform(38.0, 46.0)]
    while times[-1] < stop_time_s:
        times.append(round(times[-1] + rng.uniform(0.05, 0.4), 3))
        values.append(values[-1] if rng.random() < 0.2 else float(rng.uniform(30.0, 52.0)))
    return ReferenceSignal("table", {"times_s": times, "values_ohm": values})


def mixed_set(count, seed, stop_time_s=3.0, load_step_s=None):
    """random_scenarios with every controller; every other run on a random-walk reference,
    every fourth compensator with a saturation margin far below the minor branches'
    denominator floor (1e-12), so its clamped samples can leave it on a flat branch."""
    rng = np.random.default_rng(seed + 100)
    out = random_scenarios(count, seed, stop_time_s, load_step_s, controllers=ALL_CONTROLLERS)
    for i, s in enumerate(out):
        if i % 2:
            s = dataclasses.replace(s, reference=random_walk_reference(rng, stop_time_s))
        if i % 4 == 3:
            model = s.compensator_parameter_set
            s = dataclasses.replace(s, compensator_parameter_set=dataclasses.replace(
                model, params=model.params.replace(saturation_margin=1e-16)))
        out[i] = s
    return out


@pytest.mark.parametrize("seed, chunk, load_step_s", [(1, None, None), (2, 64, None),
                                                      (4, 17, None), (5, 100, 1.5)])
def test_random_sets_equal_the_library_path(seed, chunk, load_step_s, monkeypatch):
    """Load steps at random times (one run each), or at 1.5 s in every run (then the
    plants' minor branches are re-evaluated for many runs at once)."""
    if chunk:   # tiny chunks: load steps and reversals inside chunks, many chunk boundaries
        monkeypatch.setattr(batch, "CHUNK_ELEMENTS", chunk)
    scenarios = mixed_set(24, seed, load_step_s=load_step_s)
    results = run_batch(scenarios, "timeseries")
    kinds = {(s.controller.kind, s.controller.inverse, s.hysteresis_mode) for s in scenarios}
    assert kinds == {(kind, inverse, mode) for (kind, inverse), mode
                     in itertools.product(ALL_CONTROLLERS, HYSTERESIS_MODES)}
    saturated = {"major": 0, "minor-loop": 0}
    for scenario, result in zip(scenarios, results):
        assert result.path == "batch" and result.error is None
        scalar = run_library(scenario).data
        assert_same_series(result.data, scalar, f"{scenario.controller.kind} "
                           f"{scenario.controller.inverse} {scenario.hysteresis_mode}")
        assert result.metrics == scenario_metrics(scalar, scenario)
        if scenario.controller.feedforward:
            saturated[scenario.controller.inverse] += int(scalar["saturated"].sum())
    assert min(saturated.values()) > 0    # the clamps and the saturated memory were exercised


@pytest.mark.parametrize("values", [[45, 31, 32, 32, 31, 45], [45, 51, 50, 50, 51, 45]])
def test_minor_loop_inverse_on_flat_branches_equals_the_library_path(values, monkeypatch):
    """Clamped beyond the band, then reversed: at a margin of 1e-16 the next branch is flat
    (T_ref stays at the reversal temperature, saturated), on the hot and on the cold side."""
    base = template("load-step-continuous-pi+ff-adaptive-minor-loop").scenario(
        {"scenario.stop_time_s": 3.0})
    model = base.parameter_set
    scenario = dataclasses.replace(
        base, reference=ReferenceSignal("table", {"times_s": [0, 0.5, 1.0, 1.5, 2.0, 2.5],
                                                  "values_ohm": values}),
        compensator_parameter_set=dataclasses.replace(
            model, params=model.params.replace(saturation_margin=1e-16)))
    flat = []
    equivalent = sensing.major_equivalent       # None: the branch is flat
    monkeypatch.setattr(sensing, "major_equivalent",
                        lambda *args: flat.append(equivalent(*args)) or flat[-1])
    scalar = run_library(scenario).data
    assert flat.count(None) >= 400     # on the flat branch for the whole plateau
    assert_same_series(run_batch([scenario], "timeseries")[0].data, scalar, str(values))


def test_compensators_shared_by_a_gain_grid_equal_the_library_path():
    """Runs that differ only in gains share one inverse (and one reversal memory)."""
    scenarios = (gain_grid_scenarios(3, 5, name="heavy-continuous-pi+ff-adaptive-minor-loop")
                 + gain_grid_scenarios(2, 6, name="heavy-pi+ff-adaptive"))
    for scenario, result in zip(scenarios, run_batch(scenarios, "timeseries")):
        assert_same_series(result.data, run_library(scenario).data, scenario.name)


def test_streamed_metrics_equal_scenario_metrics(monkeypatch):
    monkeypatch.setattr(batch, "CHUNK_ELEMENTS", 200)
    scenarios = mixed_set(12, 3)
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
    """A controller option added later (here a made-up one) is refused until implemented."""
    base = template("load-step-pi+ff-adaptive")
    minor = base.scenario({"scenario.stop_time_s": 3.0, "controller.inverse": "minor-loop"})
    assert batch.unsupported_reason(minor) is None
    extended = dataclasses.make_dataclass("Extended", [("sensor_noise_ohm", float, 0.0)],
                                          bases=(type(minor.controller),), frozen=True)
    noisy = dataclasses.replace(minor, controller=extended(
        **dataclasses.asdict(minor.controller), sensor_noise_ohm=0.01))
    assert "sensor_noise_ohm = 0.01" in batch.unsupported_reason(noisy)
    with pytest.raises(BatchUnsupported, match="sensor_noise_ohm"):
        run_batch([minor, noisy])
    with pytest.raises(StudyError, match="path='library'"):
        run_many([noisy], path="batch")


def test_runs_must_share_step_and_duration():
    base = template("load-step-pi")
    with pytest.raises(ValueError, match="one step and duration"):
        run_batch([base.scenario({"scenario.stop_time_s": 3.0}),
                   base.scenario({"scenario.stop_time_s": 4.0})])


def test_run_batches_groups_by_step_and_duration_and_keeps_the_order():
    base = template("load-step-pi")
    items = [base.scenario({"scenario.stop_time_s": t, "controller.Ki_W_per_ohm_s": k})
             for t, k in ((3.0, 1.0), (4.0, 2.0), (3.0, 3.0))]
    outcomes = batch.run_batches(items)
    assert all(outcome.scenario is item for outcome, item in zip(outcomes, items))
    # t >= 10 % of the run, 1 ms steps: 0.3-3 s and 0.4-4 s
    assert [o.metrics["overall"]["samples"] for o in outcomes] == [2701, 3601, 2701]
    together = run_batch([items[0], items[2]])           # the two 3-s runs: one batch
    assert [outcomes[0].metrics, outcomes[2].metrics] == [r.metrics for r in together]
    assert all(o.path == "batch" and o.wall_time_s > 0 for o in outcomes)
    assert batch.run_batches([]) == []
