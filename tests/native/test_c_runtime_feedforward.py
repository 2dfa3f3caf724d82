"""The C compensator (c_family/runtime: feedforward, phase_lag, sensing, reachable_band) equals
the Python runtime's, step by step and bit for bit, on long random R_ref/load walks.

The walks nest reversals of the reference, return exactly to earlier levels, hold it, saturate
it at both ends of the band, change the load (also above the validity limit), start
unconnected (R_ref = 0), vary the step, and fill the minor-loop memory; both inverses, the
phase-lag filter on (alpha = tau_th, alpha = 0) and off (alpha = beta). Mid-walk the saved
state goes through C (write/read) and through Python's state() into C. Bad inputs and bad
states are refused by both with the same message (numbers compared as numbers: C prints
%.17g where Python prints repr) and change nothing.
"""
import ctypes
import math
import random

import pytest

from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.minor_loops import ReversalPoint
from sma_fmu.runtime.reachable_band import reachable_band
from sma_fmu.runtime.sensing import sense_temperature

from c_feedforward import (MINE, CParameters, CStepper, doubles_of, load_library, normalized,
                           reference_walk, same_doubles)
from c_runtime import compile_win64


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    return load_library(tmp_path_factory.mktemp("c_feedforward"))


CASES = [  # (seed, inverse, adapt_to_load, alpha ("tau": tau_th, "beta": the filter off), depth)
    (1, "major", True, "tau", 64),
    (2, "minor-loop", True, "tau", 64),
    (3, "minor-loop", True, 0.0, 4),
    (4, "minor-loop", False, "beta", 6),
    (5, "major", False, 0.0, 64),
    (6, "minor-loop", True, "beta", 2),
    (7, "minor-loop", True, "tau", 12),
    (8, "major", True, "beta", 3),
]
STEPS = 6000


def make_pair(lib, params, inverse, adapt, alpha):
    cparams = CParameters(lib, params)
    alpha = {"tau": params.tau_th, "beta": params.beta}.get(alpha, alpha)
    python = FeedforwardStepper(params, alpha=alpha, adapt_to_load=adapt, inverse=inverse)
    return python, CStepper(lib, cparams, params, alpha=alpha, adapt_to_load=adapt,
                            inverse=inverse), cparams, alpha


def compare_step(python, c, sample, worst):
    """One step through both; every output and the warning must be equal."""
    expected = python.step(*sample)
    got = c.step(*sample)
    assert got == tuple(expected), (sample, got, expected)
    for name, a, b in zip(("P_ff", "T_ref"), got, expected):
        worst[name] = max(worst[name], abs(a - b))
    warnings = [w if w is None else normalized(w) for w in (c.warning, python.warning)]
    assert warnings[0] == warnings[1], sample
    return expected


@pytest.mark.parametrize("seed, inverse, adapt, alpha, depth", CASES)
def test_the_c_compensator_equals_the_python_one(lib, params, seed, inverse, adapt, alpha,
                                                  depth):
    params = params.replace(memory_depth=depth)
    rng = random.Random(seed)
    python, c, cparams, alpha = make_pair(lib, params, inverse, adapt, alpha)
    walk = reference_walk(rng, params, STEPS)
    assert c.initial_outputs(*walk[0][:2]) == tuple(python.initial_outputs(*walk[0][:2]))
    worst = {"P_ff": 0.0, "T_ref": 0.0}
    seen = {"saturated": 0, "deepest": 0, "load warnings": 0, "reversals popped": 0,
            "pushes on a full memory": 0, "saturated hot": 0, "saturated cold": 0}
    restart = rng.randrange(STEPS // 3, 2 * STEPS // 3)
    others = []   # after the restart: the C stepper that read Python's state
    for index, sample in enumerate(walk):
        before, direction = len(python.reversals), python.direction
        outputs = compare_step(python, c, sample, worst)
        for other in others:
            assert other.step(*sample) == tuple(outputs) and other.warning == c.warning
        seen["saturated"] += outputs.saturated
        band = reachable_band(sample[1] if adapt else params.model_load, params)
        seen["saturated hot"] += outputs.saturated and sample[0] <= band.hot
        seen["saturated cold"] += outputs.saturated and sample[0] >= band.cold
        seen["deepest"] = max(seen["deepest"], len(python.reversals))
        seen["load warnings"] += bool(python.warning and "load" in python.warning)
        seen["reversals popped"] += len(python.reversals) < before
        seen["pushes on a full memory"] += before == depth and python.direction != direction
        if index % 97 == 0:
            assert same_doubles(c.state(), doubles_of(python.state())), index
        if index == restart:   # continue on fresh steppers from the saved states
            state, saved = python.state(), c.state()
            python = FeedforwardStepper(params, alpha=alpha, adapt_to_load=adapt, inverse=inverse)
            python.restore(state)
            c = CStepper(lib, cparams, params, alpha=alpha, adapt_to_load=adapt, inverse=inverse)
            c.restore(saved)
            from_python = CStepper(lib, cparams, params, alpha=alpha, adapt_to_load=adapt,
                                   inverse=inverse)
            from_python.restore(doubles_of(state))
            assert same_doubles(from_python.state(), saved)
            others.append(from_python)
    print(f"seed {seed} {inverse}: {STEPS} steps, largest |C - Python| P_ff "
          f"{worst['P_ff']:.3g} W, T_ref {worst['T_ref']:.3g} K; {seen}")
    assert worst == {"P_ff": 0.0, "T_ref": 0.0}
    assert seen["saturated hot"] > 0 and seen["saturated cold"] > 0 and seen["load warnings"] > 0
    if inverse == "minor-loop":
        assert seen["deepest"] == depth and seen["reversals popped"] > 0
        assert seen["pushes on a full memory"] > 0


@pytest.mark.parametrize("inverse", ["major", "minor-loop"])
def test_an_unconnected_start_equals_python(lib, params, inverse):
    """R_ref <= 0 before any reference: the same outputs, one warning, then the first sample;
    afterwards R_ref <= 0 is refused by both."""
    python, c, _, _ = make_pair(lib, params, inverse, True, "tau")
    worst = {"P_ff": 0.0, "T_ref": 0.0}
    assert c.initial_outputs(0.0, 0.05) == tuple(python.initial_outputs(0.0, 0.05))
    assert c.initial_outputs(-math.inf, 0.05) == tuple(python.initial_outputs(-math.inf, 0.05))
    warnings = []
    for reference in (0.0, -1.0, 0.0, -math.inf):
        compare_step(python, c, (reference, 0.05, 1e-3), worst)
        warnings.append(c.warning)
    assert warnings[0] and "unconnected" in warnings[0] and warnings[1:] == [None] * 3
    assert same_doubles(c.state(), doubles_of(python.state()))
    for reference, load, step_size in ((0.0, -1.0, 1e-3), (0.0, 0.05, 0.0)):
        message = refusal(lambda: python.step(reference, load, step_size))
        assert normalized(refusal(lambda: c.step(reference, load, step_size))) == \
            normalized(message)
    assert c.initial_outputs(40.0, 0.05) == tuple(python.initial_outputs(40.0, 0.05))
    for reference in (40.0, 41.0, 39.0, 40.0, 50.0, 30.0):
        compare_step(python, c, (reference, 0.6, 1e-3), worst)
    message = refusal(lambda: python.step(0.0, 0.05, 1e-3))
    assert normalized(refusal(lambda: c.step(0.0, 0.05, 1e-3))) == normalized(message)
    assert worst == {"P_ff": 0.0, "T_ref": 0.0}


def test_the_compensator_files_compile_clean_for_win64(tmp_path):
    """mingw-w64 under the C family's flags (-Werror): the source-code FMU's win64 build."""
    objects = compile_win64(MINE, tmp_path)
    assert objects is not None, "x86_64-w64-mingw32-gcc is not installed (.ci/run installs it)"
    assert [path.stem for path in objects] == list(MINE)
    assert all(path.stat().st_size > 0 for path in objects)


def test_the_state_from_python_continues_like_the_python_stepper(lib, params):
    """A state saved by Python, read by C, gives the same outputs afterwards."""
    params = params.replace(memory_depth=8)
    rng = random.Random(11)
    python, c, cparams, alpha = make_pair(lib, params, "minor-loop", True, "tau")
    walk = reference_walk(rng, params, 3000)
    worst = {"P_ff": 0.0, "T_ref": 0.0}
    for sample in walk[:1500]:
        python.step(*sample)
    c.restore(doubles_of(python.state()))
    assert same_doubles(c.state(), doubles_of(python.state()))
    for sample in walk[1500:]:
        compare_step(python, c, sample, worst)
    assert worst == {"P_ff": 0.0, "T_ref": 0.0}


def test_sense_temperature_and_the_band_equal_python(lib, params):
    """sense_temperature on random stacks (walk, wipe-outs, flat branches) and reachable_band."""
    cparams = CParameters(lib, params)
    rng = random.Random(5)
    temperature, saturated = ctypes.c_double(), ctypes.c_int()
    error, out = ctypes.create_string_buffer(512), (ctypes.c_double * 2)()
    for _ in range(3000):
        load = rng.choice([0.0, 0.05, 0.2, rng.uniform(0.0, 0.5)])
        band = reachable_band(load, params)
        assert lib.band(cparams.pointer, load, out, error) == 0
        assert (out[0], out[1]) == tuple(band)
        points, level = [], rng.uniform(20.0, 90.0)
        for k in range(rng.randint(0, 10)):
            level += (-1) ** k * rng.uniform(0.0, 20.0)
            xi = rng.choice([rng.uniform(0.0, 1.0), 0.0, 1.0, 0.5])
            points.append(ReversalPoint(level, xi))
            if rng.random() < 0.1:
                points.append(ReversalPoint(level, xi))   # a flat branch
        direction = rng.choice((1, -1))
        resistance = rng.uniform(band.hot - 1.0, band.cold + 1.0)
        expected = sense_temperature(resistance, load, direction, params, points)
        flat = (ctypes.c_double * max(1, 2 * len(points)))(*[v for p in points for v in p])
        assert lib.sense(cparams.pointer, resistance, load, direction, flat, len(points),
                         ctypes.byref(temperature), ctypes.byref(saturated), error) == 0
        assert (temperature.value, bool(saturated.value)) == tuple(expected)


# ---------------------------------------------------------------- refusals

def refusal(call):
    """The message of the ValueError (or RuntimeError) `call` raises."""
    with pytest.raises((ValueError, RuntimeError)) as caught:
        call()
    return str(caught.value)


@pytest.mark.parametrize("reference, load, step_size", [
    (math.nan, 0.05, 1e-3), (-1.0, 0.05, 1e-3), (0.0, 0.05, 1e-3), (math.inf, 0.05, 1e-3),
    (40.0, -1.0, 1e-3), (40.0, math.nan, 1e-3), (40.0, math.inf, 1e-3), (40.0, 0.05, 0.0),
    (40.0, 0.05, -1e-3), (40.0, 0.05, math.nan), (40.0, 1.7e308, 1e-3),
])
def test_bad_inputs_are_refused_alike_and_change_nothing(lib, params, reference, load,
                                                         step_size):
    python, c, _, _ = make_pair(lib, params, "minor-loop", True, "tau")
    walk = reference_walk(random.Random(3), params, 400)
    worst = {"P_ff": 0.0, "T_ref": 0.0}
    for sample in walk[:200]:
        compare_step(python, c, sample, worst)
    before = c.state()
    message = refusal(lambda: python.step(reference, load, step_size))
    assert normalized(refusal(lambda: c.step(reference, load, step_size))) == normalized(message)
    assert same_doubles(c.state(), before)
    for sample in walk[200:]:
        compare_step(python, c, sample, worst)


def test_bad_arguments_at_the_start_are_refused_alike(lib, params):
    cparams = CParameters(lib, params)
    for keywords in ({"alpha": -1.0}, {"alpha": math.inf}, {"beta": 0.0}, {"beta": math.nan},
                     {"model_load": -0.1}, {"inverse": "minor"}, {"inverse": "Major"},
                     {"inverse": "50%s%n"}):
        message = refusal(lambda: FeedforwardStepper(params, **keywords))
        got = refusal(lambda: CStepper(lib, cparams, params, **keywords))
        assert normalized(got) == normalized(message), keywords
    python = FeedforwardStepper(params)
    c = CStepper(lib, cparams, params)
    for reference, load in ((math.nan, 0.0), (40.0, -1.0), (40.0, 1.7e308), (-1.0, math.nan)):
        message = refusal(lambda: python.initial_outputs(reference, load))
        got = refusal(lambda: c.initial_outputs(reference, load))
        assert normalized(got) == normalized(message)
    python.step(40.0, 0.05, 1e-3)
    c.step(40.0, 0.05, 1e-3)
    assert refusal(lambda: c.initial_outputs(40.0, 0.05)) == refusal(
        lambda: python.initial_outputs(40.0, 0.05))


def test_a_non_finite_filter_output_is_refused_alike(lib, params):
    """alpha = 1e308 s, beta = 1e-300 s: the filter's output leaves the double range."""
    c = CStepper(lib, CParameters(lib, params), params, alpha=1e308, beta=1e-300)
    python = FeedforwardStepper(params, alpha=1e308, beta=1e-300)
    worst = {"P_ff": 0.0, "T_ref": 0.0}
    refused = 0
    for reference in (40.0, 41.0, 40.0, 45.0, 38.0, 47.0, 36.0):
        try:
            compare_step(python, c, (reference, 0.05, 1e-3), worst)
        except ValueError as error:   # Python refused: C must too, with the same words
            before = c.state()
            got = refusal(lambda: c.step(reference, 0.05, 1e-3))
            assert normalized(got) == normalized(str(error))
            assert "phase-lag filter output" in got and same_doubles(c.state(), before)
            refused += 1
    assert refused > 0 and worst == {"P_ff": 0.0, "T_ref": 0.0}


def _bad_states(state):
    """(what to change in a Python state dict, the C doubles, the name both messages give)."""
    def changed(**entries):
        new = {**state, **entries}
        return new, doubles_of(new)

    def changed_filter(**entries):
        return changed(filter={**state["filter"], **entries})
    point = list(state["reversals"][0])
    yield changed(direction=0) + ("direction",)
    yield changed(direction=2) + ("direction",)
    yield changed(previous_reference=-1.0) + ("previous_reference",)
    yield changed(previous_reference=0.0) + ("previous_reference",)
    yield changed(previous_reference=math.inf) + ("previous_reference",)
    yield changed(previous_temperature=-273.15) + ("previous_temperature",)
    yield changed(previous_temperature=-300.0) + ("previous_temperature",)
    yield changed(previous_temperature=math.inf) + ("previous_temperature",)
    yield changed(previous_fraction=1.5) + ("previous_fraction",)
    yield changed(previous_fraction=-0.1) + ("previous_fraction",)
    yield changed(previous_fraction=None) + ("previous_fraction",)
    yield changed(previous_temperature=None) + ("previous_temperature",)
    yield changed(previous_exponent=math.inf, previous_slope=1e4) + ("previous_exponent",)
    yield changed(previous_exponent=0.5, previous_slope=0.0) + ("previous_slope",)
    yield changed(previous_exponent=0.5, previous_slope=-2e4) + ("previous_slope",)
    yield changed(previous_exponent=0.5, previous_slope=math.inf) + ("previous_slope",)
    yield changed(previous_exponent=0.5) + ("previous_exponent and previous_slope",)
    yield changed(reversals=state["reversals"] + [[-274.0, 0.5]]) + ("reversals[",)
    yield changed(reversals=[[point[0], 1.5]] + state["reversals"][1:]) + ("reversals[0]",)
    yield changed(reversals=[[math.inf, 0.5]]) + ("reversals[0]",)
    yield changed(reversals=[point] * 9) + ("reversals must be",)
    yield changed_filter(previous_input=math.inf) + ("previous_input",)
    yield changed_filter(previous_output=None) + ("previous_input",)


def test_bad_states_are_refused_alike_and_change_nothing(lib, params):
    params = params.replace(memory_depth=8)
    python, c, cparams, alpha = make_pair(lib, params, "minor-loop", True, "tau")
    walk = reference_walk(random.Random(9), params, 1200)
    worst = {"P_ff": 0.0, "T_ref": 0.0}
    for sample in walk[:600]:
        compare_step(python, c, sample, worst)
    state, saved = python.state(), c.state()
    assert state["reversals"], "the walk should leave reversal points"
    for bad, doubles, name in _bad_states(state):
        message = refusal(lambda: python.restore(bad))
        got = refusal(lambda: c.restore(doubles))
        assert name in message and name in got, (name, message, got)
        if not name.startswith("reversals"):   # the list-valued entries print differently
            assert normalized(got) == normalized(message)
        assert same_doubles(c.state(), saved) and python.state() == state
    for doubles in (saved[:8], saved + [0.0], saved[:-1], saved[:8] + [0.5] + saved[9:],
                    saved[:8] + [-1.0] + saved[9:]):
        assert "compensator state" in refusal(lambda: c.restore(doubles)) \
            or "reversals must be" in refusal(lambda: c.restore(doubles))
        assert same_doubles(c.state(), saved)
    for sample in walk[600:]:
        compare_step(python, c, sample, worst)
    assert worst == {"P_ff": 0.0, "T_ref": 0.0}
