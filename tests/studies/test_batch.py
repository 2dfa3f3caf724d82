"""The batch engine equals the scalar library path (<= 1e-10) on random sets of runs.

The sets (sma_fmu.studies.random_set, also the benchmark's) mix every controller (both
inverses, with the fixed and the adaptive compensator) in both hysteresis modes with random
gains, filters, loads, references, wire and model parameters; some runs get a random
piecewise-linear reference, so the compensators reverse at different samples, on plateaus
and outside the band the wire can reach. Nested minor loops (spec section 6: a stack of
reversal points with wiping out) come from references of several superimposed frequencies
with a start inside the transformation and load steps, with the default memory depth and
with a depth of 4 (the two oldest points dropped), in the plant and in the compensator.

The batch's numpy exp and log may differ from the math module's in the last bit, so the
series agree to rounding, not bit for bit, and the metrics are compared to rounding too.
"""
import dataclasses
import itertools
import math

import numpy as np
import pytest

import sma_fmu.runtime.feedforward as runtime_feedforward
import sma_fmu.runtime.plant as runtime_plant
import sma_fmu.runtime.sensing as runtime_sensing
import sma_fmu.studies.batch.engine as batch_engine
import sma_fmu.studies.batch.minor_loops as batch_minor_loops
import sma_fmu.studies.batch.plant as batch_plant
from sma_fmu.cosim.loop import LibraryCompensator, LibraryPlant, run_library, run_loop
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.runtime.checks import HYSTERESIS_MODES
from sma_fmu.runtime.constants import HEATING
from sma_fmu.runtime.minor_loops import DENOMINATOR_FLOOR, major_value, value_of
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.signals import ReferenceSignal
from sma_fmu.studies.batch.inputs import BatchInputs
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


def assert_same_metrics(actual, expected):
    """scenario_metrics records equal to rounding: numbers to 1e-12 relative, the rest exactly."""
    assert actual.keys() == expected.keys()
    for key, value in expected.items():
        if isinstance(value, dict):
            assert_same_metrics(actual[key], value)
        elif isinstance(value, list) and value and isinstance(value[0], dict):
            assert len(actual[key]) == len(value), key
            for part, reference in zip(actual[key], value):
                assert_same_metrics(part, reference)
        elif isinstance(value, float) and not isinstance(actual[key], bool):
            assert actual[key] == pytest.approx(value, rel=1e-12, abs=1e-15), key
        else:
            assert actual[key] == value, key


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
        monkeypatch.setattr(batch_engine, "CHUNK_ELEMENTS", chunk)
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
        assert_same_metrics(result.metrics, scenario_metrics(scalar, scenario))
        if scenario.controller.feedforward:
            saturated[scenario.controller.inverse] += int(scalar["saturated"].sum())
    assert min(saturated.values()) > 0    # the clamps and the saturated memory were exercised


def is_flat(points, kept, constants, direction):
    """Whether temperature_on_stack ended on a flat branch (section 6: a denominator below
    the floor), recomputed from the stack it kept with the runtime's own helpers."""
    if not kept:
        return False
    heating, total = direction == HEATING, constants.M
    top = points[kept - 1]
    value_A, major_A = value_of(top, total, heating), major_value(top.temperature, constants,
                                                                   heating)
    value_B = major_B = 0.0
    if kept >= 2:
        below = points[kept - 2]
        value_B = value_of(below, total, heating)
        major_B = major_value(below.temperature, constants, heating)
    return abs(major_A - major_B) < DENOMINATOR_FLOOR or abs(value_A - value_B) < DENOMINATOR_FLOOR


@pytest.mark.parametrize("values", [[45, 51, 50, 50, 51, 45], [45, 51, 50, 51, 50, 51, 45]])
def test_minor_loop_inverse_on_flat_branches_equals_the_library_path(values, monkeypatch):
    """Clamped beyond the cold end of the band, then reversed (once, or back and forth):
    at a margin of 1e-16 the branch is flat (T_ref stays at the top point's temperature,
    saturated) for the whole plateau."""
    base = template("load-step-continuous-pi+ff-adaptive-minor-loop").scenario(
        {"scenario.stop_time_s": 3.0})
    model = base.parameter_set
    scenario = dataclasses.replace(
        base, reference=ReferenceSignal("table", {"times_s": [0.5 * i for i in range(len(values))],
                                                  "values_ohm": values}),
        compensator_parameter_set=dataclasses.replace(
            model, params=model.params.replace(saturation_margin=1e-16)))
    flat = []
    walk = runtime_sensing.temperature_on_stack       # the stepper's walk (invert_on_stack)

    def watched(xi_mf, xi_p, constants, direction, points, margin, count=None):
        sensed, kept = walk(xi_mf, xi_p, constants, direction, points, margin, count)
        flat.append(is_flat(points, kept, constants, direction))
        return sensed, kept
    monkeypatch.setattr(runtime_sensing, "temperature_on_stack", watched)
    scalar = run_library(scenario).data
    assert sum(flat) >= 400     # on a flat branch for a whole plateau
    assert_same_series(run_batch([scenario], "timeseries")[0].data, scalar, str(values))


def multi_frequency_reference(stop_time_s):
    """R_ref of three superimposed frequencies (0.7 Hz decaying, 2.3 Hz, 6.1 Hz) as a table
    every 10 ms: reversals inside reversals, so the stacks nest."""
    times = [round(0.01 * i, 2) for i in range(int(round(stop_time_s / 0.01)) + 1)]
    values = [41.5 + 5.0 * math.exp(-t / 2.5) * math.sin(2.0 * math.pi * 0.7 * t)
              + 1.2 * math.sin(2.0 * math.pi * 2.3 * t + 1.0)
              + 0.5 * math.sin(2.0 * math.pi * 6.1 * t) for t in times]
    return times, values


def nested_scenarios(stop_time_s=6.0, depths=(4, 64)):
    """Every controller in both modes on the multi-frequency reference, starting at 60 degC
    (inside the transformation), with load steps at 2 s and 4 s, for each memory depth of
    the wire and of the compensator's model (overrides wire.memory_depth, model.memory_depth)."""
    times, values = multi_frequency_reference(stop_time_s)
    base = template("load-step-continuous-pi+ff-adaptive-minor-loop")
    return [base.scenario({
        "scenario.stop_time_s": stop_time_s, "reference.kind": "table",
        "reference.times_s": times, "reference.values_ohm": values,
        "plant.T_start_degC": 60.0, "plant.hysteresis_mode": mode,
        "load.times_s": [0.0, 2.0, 4.0], "load.values_kg": [0.01, 0.08, 0.03],
        "controller.kind": kind, "controller.inverse": inverse,
        "wire.memory_depth": depth, "model.memory_depth": depth})
        for (kind, inverse), mode, depth in itertools.product(
            ALL_CONTROLLERS, HYSTERESIS_MODES, depths)]


class PushCounter:
    """Wraps a module's push_reversal: pushes, pushes that dropped the two oldest points,
    and the largest stack, per module name."""

    def __init__(self, monkeypatch, **modules):
        self.counts = {}
        for name, module in modules.items():
            monkeypatch.setattr(module, "push_reversal", self._wrap(name, module.push_reversal))

    def _wrap(self, name, push):
        def counted(points, temperature, xi_mf, depth):
            pushes, drops, deepest = self.counts.get(name, (0, 0, 0))
            drops += len(points) + 1 > depth
            push(points, temperature, xi_mf, depth)
            self.counts[name] = (pushes + 1, drops, max(deepest, len(points)))
        return counted


@pytest.mark.parametrize("engine", ["default", "vectorized events, small windows and chunks"])
def test_nested_minor_loops_equal_the_library_path(engine, monkeypatch):
    """Nested minor loops, wiped-out loops, load steps and a depth of 4 (points dropped), in
    the plant and in the compensator, both modes, both inverses: every column <= 1e-10.

    The second engine handles every plant event with numpy (no run-by-run path), walks the
    compensators in windows of 2 samples and cuts the run into chunks of 3 steps, so events
    fall on chunk boundaries and on the first sample of a chunk."""
    if engine != "default":
        monkeypatch.setattr(batch_plant, "FEW_RUNS", 0)
        monkeypatch.setattr(batch_minor_loops, "WINDOW", 2)
        monkeypatch.setattr(batch_engine, "CHUNK_ELEMENTS", 60)
    scenarios = nested_scenarios()
    results = run_batch(scenarios, "timeseries")
    counter = PushCounter(monkeypatch, plant=runtime_plant, compensator=runtime_feedforward)
    seen = {}
    for scenario, result in zip(scenarios, results):
        counter.counts.clear()
        scalar = run_library(scenario).data
        label = (f"{scenario.controller.kind} {scenario.controller.inverse} "
                 f"{scenario.hysteresis_mode} depth {scenario.params.memory_depth}")
        assert result.path == "batch" and result.error is None, label
        assert_same_series(result.data, scalar, label)
        assert_same_metrics(result.metrics, scenario_metrics(scalar, scenario))
        for name, (pushes, drops, deepest) in counter.counts.items():
            key = (name, scenario.params.memory_depth)
            total = seen.get(key, (0, 0, 0))
            seen[key] = (total[0] + pushes, total[1] + drops, max(total[2], deepest))
    # what the set exercised, on the scalar path: nesting beyond 4 points at depth 64, and
    # drops at depth 4, in the plant and in the compensator
    for name in ("plant", "compensator"):
        assert seen[(name, 64)][1] == 0 and seen[(name, 64)][2] >= 5, (name, seen)
        assert seen[(name, 4)][1] >= 2 and seen[(name, 4)][2] == 4, (name, seen)


def test_the_batch_stacks_are_the_scalar_stacks_and_never_exceed_the_depth(monkeypatch):
    """After every plant step and every compensator chunk no stack is deeper than its
    memory_depth, and at the end each run's stacks are the scalar path's (the plant's to
    1e-10, the compensator's bit for bit: its points come from the runtime's functions)."""
    scenarios = [s for s in nested_scenarios(stop_time_s=4.0) if s.hysteresis_mode == "continuous"
                 or s.controller.inverse == "minor-loop"]
    made = {}

    class CheckedPlant(batch_engine.BatchPlant):
        def __init__(self, inputs, ordered):
            super().__init__(inputs, ordered)
            made["plant"], made["order"], made["deepest"] = self, ordered, 0

        def step(self, power):
            super().step(power)
            assert (self.reversal_count <= self.depth).all()
            made["deepest"] = max(made["deepest"], int(self.reversal_count.max()))

    class CheckedFeedforward(batch_engine.BatchFeedforward):
        def __init__(self, inputs, ordered):
            super().__init__(inputs, ordered)
            made["feedforward"], made["stacked"] = self, 0

        def chunk(self, start, stop):
            out = super().chunk(start, stop)
            memory = self.minor
            assert all(len(points) <= depth for points, depth in zip(memory.points,
                                                                      memory.depths))
            made["stacked"] = max([made["stacked"]] + [len(points) for points in memory.points])
            return out
    monkeypatch.setattr(batch_engine, "BatchPlant", CheckedPlant)
    monkeypatch.setattr(batch_engine, "BatchFeedforward", CheckedFeedforward)
    run_batch(scenarios, "metrics")
    plant, feedforward, order = made["plant"], made["feedforward"], made["order"]
    assert made["deepest"] >= 4 and made["stacked"] >= 4
    position = {id(scenario): run for run, scenario in enumerate(order)}
    minor_runs = feedforward.runs.tolist()
    compared = 0
    for scenario in scenarios:
        run = position[id(scenario)]
        library_plant = LibraryPlant(scenario)
        compensator = LibraryCompensator(scenario) if scenario.controller.feedforward else None
        run_loop(scenario, library_plant, compensator)
        expected = library_plant.stepper.reversals
        got = plant.reversals(run)
        assert len(got) == len(expected) <= scenario.params.memory_depth, scenario.name
        if expected:
            np.testing.assert_allclose(got, expected, rtol=0, atol=TOLERANCE)
        if scenario.controller.inverse == "minor-loop":
            column = feedforward.of_run[minor_runs.index(run)] - feedforward.split
            assert feedforward.minor.points[column] == compensator.stepper.reversals
            compared += len(compensator.stepper.reversals) > 0
    assert compared >= 2


@pytest.mark.parametrize("few_runs", [0, 1000])
def test_plant_events_equal_the_scalar_plant_step_by_step(few_runs, monkeypatch):
    """BatchPlant against PlantStepper, step by step, under a power that chatters every step
    (a one-on one-off drive) for a third of the runs and swings in decaying nested loops for
    the others, with depths 2 to 5 and 64 and a load step: R, T and the stacks after every
    step; every event handled with numpy (0) or run by run (1000)."""
    monkeypatch.setattr(batch_plant, "FEW_RUNS", few_runs)
    counter = PushCounter(monkeypatch, plant=runtime_plant)
    rng = np.random.default_rng(7)
    depths = [2, 3, 4, 5, 64]
    scenarios = []
    for index, scenario in enumerate(random_scenarios(30, 11, 1.5, load_step_s=0.8)):
        params = scenario.params.replace(memory_depth=depths[index % len(depths)])
        scenarios.append(dataclasses.replace(
            scenario, T_start=float(rng.uniform(50.0, 80.0)),
            hysteresis_mode="switch" if index % 6 == 5 else "continuous",
            parameter_set=dataclasses.replace(scenario.parameter_set, params=params)))
    inputs = BatchInputs(scenarios)
    plant = batch_engine.BatchPlant(inputs, scenarios)
    steppers = [PlantStepper(s.params, s.T_start, s.hysteresis_mode, s.load.value(0.0))
                for s in scenarios]
    hold = np.array([(65.0 - s.params.T_room) / s.params.K_th for s in scenarios])
    phase = rng.uniform(0.0, 2.0 * math.pi, len(scenarios))
    chatter = np.arange(len(scenarios)) % 3 == 0
    changes, h = set(inputs.change_steps), inputs.step_s
    for k in range(inputs.steps):
        if k in changes:
            plant.set_segments(inputs.segment_row(k), inputs.segment_row(k - 1))
        t = k * h
        swing = hold * (1.0 + 0.8 * math.exp(-t / 0.6) * np.sin(2.0 * math.pi * 3.0 * t + phase)
                        + 0.1 * math.sin(2.0 * math.pi * 29.0 * t))
        power = np.maximum(np.where(chatter, 2.0 * hold * (k % 2), swing), 0.0)
        plant.step(power)
        for stepper, scenario, p in zip(steppers, scenarios, power.tolist()):
            stepper.step(p, scenario.load.value(t), h)
        expected = np.array([len(s.reversals) for s in steppers])
        assert np.array_equal(plant.reversal_count, expected), k
        assert (plant.reversal_count <= plant.depth).all()
        np.testing.assert_allclose(plant.R, [s.outputs.R for s in steppers], rtol=0,
                                   atol=TOLERANCE)
        np.testing.assert_allclose(plant.temperature, [s.temperature for s in steppers],
                                   rtol=0, atol=TOLERANCE)
        if k % 50 == 0 or k == inputs.steps - 1:
            for run, stepper in enumerate(steppers):
                if stepper.reversals:
                    np.testing.assert_allclose(plant.reversals(run), stepper.reversals,
                                               rtol=0, atol=TOLERANCE)
    pushes, drops, deepest = counter.counts["plant"]
    assert pushes >= 1000 and drops >= 10 and deepest >= 5


def test_compensators_shared_by_a_gain_grid_equal_the_library_path():
    """Runs that differ only in gains share one inverse (and one reversal memory)."""
    scenarios = (gain_grid_scenarios(3, 5, name="heavy-continuous-pi+ff-adaptive-minor-loop")
                 + gain_grid_scenarios(2, 6, name="heavy-pi+ff-adaptive"))
    for scenario, result in zip(scenarios, run_batch(scenarios, "timeseries")):
        assert_same_series(result.data, run_library(scenario).data, scenario.name)


def test_streamed_metrics_equal_scenario_metrics(monkeypatch):
    monkeypatch.setattr(batch_engine, "CHUNK_ELEMENTS", 200)
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
    assert batch_engine.unsupported_reason(minor) is None
    extended = dataclasses.make_dataclass("Extended", [("sensor_noise_ohm", float, 0.0)],
                                          bases=(type(minor.controller),), frozen=True)
    noisy = dataclasses.replace(minor, controller=extended(
        **dataclasses.asdict(minor.controller), sensor_noise_ohm=0.01))
    assert "sensor_noise_ohm = 0.01" in batch_engine.unsupported_reason(noisy)
    with pytest.raises(BatchUnsupported, match="sensor_noise_ohm"):
        run_batch([minor, noisy])
    with pytest.raises(StudyError, match="path='library'"):
        run_many([noisy], path="batch")
    shaped = base.scenario({"scenario.stop_time_s": 3.0, "controller.shaping": "reachable"})
    assert "shaping 'reachable'" in batch_engine.unsupported_reason(shaped)


def test_runs_must_share_step_and_duration():
    base = template("load-step-pi")
    with pytest.raises(ValueError, match="one step and duration"):
        run_batch([base.scenario({"scenario.stop_time_s": 3.0}),
                   base.scenario({"scenario.stop_time_s": 4.0})])


def test_run_batches_groups_by_step_and_duration_and_keeps_the_order():
    base = template("load-step-pi")
    items = [base.scenario({"scenario.stop_time_s": t, "controller.Ki_W_per_ohm_s": k})
             for t, k in ((3.0, 1.0), (4.0, 2.0), (3.0, 3.0))]
    outcomes = batch_engine.run_batches(items)
    assert all(outcome.scenario is item for outcome, item in zip(outcomes, items))
    # t >= 10 % of the run, 1 ms steps: 0.3-3 s and 0.4-4 s
    assert [o.metrics["overall"]["samples"] for o in outcomes] == [2701, 3601, 2701]
    together = run_batch([items[0], items[2]])           # the two 3-s runs: one batch
    assert [outcomes[0].metrics, outcomes[2].metrics] == [r.metrics for r in together]
    assert all(o.path == "batch" and o.wall_time_s > 0 for o in outcomes)
    assert batch_engine.run_batches([]) == []
