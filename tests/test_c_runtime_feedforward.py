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
import re

import pytest

from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.minor_loops import ReversalPoint
from sma_fmu.runtime.parameters import PARAMETER_SPECS
from sma_fmu.runtime.reachable_band import reachable_band
from sma_fmu.runtime.sensing import sense_temperature

from c_runtime import compile_runtime

RUNTIME = ("sma_message", "checks", "state_entries", "lattice", "thermal", "phases",
           "constant_load", "minor_loops", "validity", "parameters", "reachable_band",
           "sensing", "phase_lag", "feedforward")

# a test-only front over the C API: parameters and steppers on the heap, errors as text
SHIM = r"""
#include <stdlib.h>
#include <string.h>
#include "feedforward.h"
#include "reachable_band.h"
#include "sensing.h"

static void copy_error(char *error, const SmaMessage *m) { memcpy(error, m->text, 512); }

void *params_new(const double *values, char *error) {
    SmaMessage m; WireParameters *p = malloc(sizeof *p);
    if (wire_parameters_from_values(p, values, &m)) { copy_error(error, &m); free(p); return NULL; }
    return p;
}
void params_free(void *p) { free(p); }

void *ff_new(const void *params, double alpha, double beta, double model_load, int adapt,
             const char *inverse, char *error) {
    SmaMessage m; FeedforwardStepper *s = malloc(sizeof *s);
    if (feedforward_stepper_init(s, params, alpha, beta, model_load, adapt, inverse, &m)) {
        copy_error(error, &m); feedforward_stepper_free(s); free(s); return NULL;
    }
    return s;
}
void ff_free(void *s) { feedforward_stepper_free(s); free(s); }
static void put(const FeedforwardOutputs *o, double *out, int *saturated) {
    out[0] = o->P_ff; out[1] = o->T_ref; *saturated = o->saturated;
}
int ff_step(void *s, double r, double load, double h, double *out, int *saturated,
            char *warning, char *error) {
    SmaMessage m; FeedforwardOutputs o; FeedforwardStepper *f = s;
    if (feedforward_stepper_step(f, r, load, h, &o, &m)) { copy_error(error, &m); return 1; }
    put(&o, out, saturated); memcpy(warning, f->warning, sizeof f->warning); return 0;
}
int ff_initial(void *s, double r, double load, double *out, int *saturated, char *error) {
    SmaMessage m; FeedforwardOutputs o;
    if (feedforward_stepper_initial_outputs(s, r, load, &o, &m)) { copy_error(error, &m); return 1; }
    put(&o, out, saturated); return 0;
}
size_t ff_state_size(const void *s) { return feedforward_stepper_state_size(s); }
void ff_state_write(const void *s, double *out) { feedforward_stepper_state_write(s, out); }
int ff_state_read(void *s, const double *in, size_t count, char *error) {
    SmaMessage m;
    if (feedforward_stepper_state_read(s, in, count, &m)) { copy_error(error, &m); return 1; }
    return 0;
}
int band(const void *params, double load, double *out, char *error) {
    SmaMessage m; ResistanceBand b;
    if (reachable_band(load, params, &b, &m)) { copy_error(error, &m); return 1; }
    out[0] = b.hot; out[1] = b.cold; return 0;
}
int sense(const void *params, double r, double load, int direction, const double *points,
          size_t count, double *temperature, int *saturated, char *error) {
    SmaMessage m; SensedTemperature t; ReversalPoint stack[64]; size_t i;
    for (i = 0; i < count && i < 64; i++) { stack[i].temperature = points[2 * i];
                                            stack[i].xi_MF = points[2 * i + 1]; }
    if (sense_temperature(r, load, direction, params, stack, count, &t, &m)) {
        copy_error(error, &m); return 1;
    }
    *temperature = t.temperature; *saturated = t.saturated; return 0;
}
"""

D, P, I, S, C = (ctypes.c_double, ctypes.c_void_p, ctypes.c_int, ctypes.c_size_t,
                 ctypes.c_char_p)
DP, IP = ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_int)
SIGNATURES = {
    "params_new": (P, [DP, C]), "params_free": (None, [P]),
    "ff_new": (P, [P, D, D, D, I, C, C]), "ff_free": (None, [P]),
    "ff_step": (I, [P, D, D, D, DP, IP, C, C]), "ff_initial": (I, [P, D, D, DP, IP, C]),
    "ff_state_size": (S, [P]), "ff_state_write": (None, [P, DP]),
    "ff_state_read": (I, [P, DP, S, C]), "band": (I, [P, D, DP, C]),
    "sense": (I, [P, D, D, I, DP, S, DP, IP, C]),
}


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    library = compile_runtime(RUNTIME, tmp_path_factory.mktemp("c_feedforward"),
                              extra_source=SHIM)
    for name, (restype, argtypes) in SIGNATURES.items():
        function = getattr(library, name)
        function.restype, function.argtypes = restype, argtypes
    return library


class CParameters:
    """WireParameters in C from a Python WireParameters (PARAMETER_SPECS order)."""

    def __init__(self, lib, params):
        values = [getattr(params, spec.name) for spec in PARAMETER_SPECS]
        array = (ctypes.c_double * len(values))(*[math.nan if v is None else float(v)
                                                 for v in values])
        error = ctypes.create_string_buffer(512)
        self.lib, self.pointer = lib, lib.params_new(array, error)
        assert self.pointer, error.value.decode()

    def __del__(self):
        self.lib.params_free(self.pointer)


class CStepper:
    """The C FeedforwardStepper with Python's method names; refusals raise ValueError."""

    def __init__(self, lib, cparams, params, alpha=None, beta=None, model_load=None,
                 adapt_to_load=True, inverse="major"):
        self.lib, self.cparams = lib, cparams   # cparams outlives the stepper
        error = ctypes.create_string_buffer(512)
        self.pointer = lib.ff_new(
            cparams.pointer, params.phase_lag_alpha if alpha is None else alpha,
            params.beta if beta is None else beta,
            params.model_load if model_load is None else model_load, int(adapt_to_load),
            None if inverse is None else inverse.encode(), error)
        if not self.pointer:
            raise ValueError(error.value.decode())
        self._out, self._saturated = (ctypes.c_double * 2)(), ctypes.c_int()
        self._warning, self._error = ctypes.create_string_buffer(256), ctypes.create_string_buffer(512)
        self.warning = None

    def __del__(self):
        if getattr(self, "pointer", None):
            self.lib.ff_free(self.pointer)

    def _outputs(self):
        return self._out[0], self._out[1], bool(self._saturated.value)

    def step(self, reference, load, step_size):
        if self.lib.ff_step(self.pointer, reference, load, step_size, self._out, self._saturated,
                            self._warning, self._error):
            raise ValueError(self._error.value.decode())
        self.warning = self._warning.value.decode() or None
        return self._outputs()

    def initial_outputs(self, reference, load):
        if self.lib.ff_initial(self.pointer, reference, load, self._out, self._saturated,
                               self._error):
            raise ValueError(self._error.value.decode())
        return self._outputs()

    def state(self):
        out = (ctypes.c_double * self.lib.ff_state_size(self.pointer))()
        self.lib.ff_state_write(self.pointer, out)
        return list(out)

    def restore(self, values):
        array = (ctypes.c_double * len(values))(*values)
        if self.lib.ff_state_read(self.pointer, array, len(values), self._error):
            raise ValueError(self._error.value.decode())


def doubles_of(state):
    """Python's state() dict in the C layout (feedforward.h): None as NaN."""
    def number(value):
        return math.nan if value is None else float(value)
    out = [float(state["direction"]), number(state["previous_reference"]),
           number(state["previous_temperature"]), number(state["previous_fraction"]),
           number(state["filter"]["previous_input"]), number(state["filter"]["previous_output"]),
           float(len(state["reversals"]))]
    for temperature, xi_mf in state["reversals"]:
        out += [float(temperature), float(xi_mf)]
    return out


def same_doubles(a, b):
    return len(a) == len(b) and all(x == y or (math.isnan(x) and math.isnan(y))
                                    for x, y in zip(a, b))


_NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+(?:\.\d*)?(?:[eE][-+]?\d+)?|inf|nan)(?![\w.])")


def normalized(text):
    """A message with every number as Python's repr of its float ('-1' and '-1.0' agree)."""
    return _NUMBER.sub(lambda match: repr(float(match.group())), text)


# ---------------------------------------------------------------- the walks

def reference_walk(rng, params, steps):
    """(R_ref [ohm], load [kg], h [s]) samples: nested reversals, returns to exact earlier
    levels, holds, saturation at both ends, load changes, a few varied steps."""
    load, h = rng.choice([0.0, 0.05, 0.15]), 1e-3
    history = []
    samples = []
    if rng.random() < 0.5:                      # unconnected start
        samples += [(0.0, load, h)] * rng.randint(1, 3)
    while len(samples) < steps:
        band = reachable_band(load, params)
        hot, cold, span = band.hot, band.cold, band.cold - band.hot
        kind = rng.random()
        if kind < 0.35:                         # nested reversals of shrinking amplitude
            centre = rng.uniform(hot + 0.2 * span, cold - 0.2 * span)
            amplitude = rng.uniform(0.05, 0.45) * span
            sign = rng.choice((1, -1))
            for _ in range(rng.randint(2, 12)):
                goal = centre + sign * amplitude
                start = samples[-1][0] if samples and samples[-1][0] > 0 else centre
                for k in range(1, rng.randint(2, 8) + 1):
                    samples.append((start + (goal - start) * k / 8.0, load, h))
                samples.append((goal, load, h))
                history.append(goal)
                amplitude *= rng.uniform(0.5, 0.95)
                sign = -sign
        elif kind < 0.5 and history:            # back exactly to earlier levels
            for _ in range(rng.randint(1, 4)):
                samples += [(rng.choice(history), load, h)] * rng.randint(1, 3)
        elif kind < 0.6:                        # beyond either end (saturation), held
            level = rng.choice((hot - rng.uniform(0.0, 2.0), cold + rng.uniform(0.0, 2.0),
                                hot, cold, hot + 1e-9 * span, cold - 1e-9 * span))
            samples += [(level, load, h)] * rng.randint(1, 5)
        elif kind < 0.75:                       # a random ramp
            level = rng.uniform(hot - 0.5, cold + 0.5)
            start = samples[-1][0] if samples and samples[-1][0] > 0 else level
            n = rng.randint(3, 30)
            samples += [(start + (level - start) * k / n, load, h) for k in range(1, n + 1)]
        elif kind < 0.85:                       # a load change (sometimes past the limit)
            load = rng.choice([0.0, 0.02, 0.05, 0.1, 0.25, rng.uniform(0.0, 0.3),
                               params.load_max * rng.uniform(1.0, 1.6)])
        elif kind < 0.9:                        # a continuously varying load
            for _ in range(rng.randint(5, 40)):
                load = max(0.0, load + rng.gauss(0.0, 0.01))
                samples.append((rng.uniform(hot, cold), load, h))
        elif kind < 0.95:                       # another step size
            h = rng.choice([1e-3, 2e-3, 5e-4, 1e-2, rng.uniform(1e-5, 0.05)])
        else:                                   # noise around the last level
            last = samples[-1][0] if samples and samples[-1][0] > 0 else 0.5 * (hot + cold)
            samples += [(last + rng.gauss(0.0, 0.01 * span), load, h)
                        for _ in range(rng.randint(2, 20))]
    return samples[:steps]


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
    seen = {"saturated": 0, "deepest": 0, "load warnings": 0, "reversals popped": 0}
    restart = rng.randrange(STEPS // 3, 2 * STEPS // 3)
    for index, sample in enumerate(walk):
        before = len(python.reversals)
        outputs = compare_step(python, c, sample, worst)
        seen["saturated"] += outputs.saturated
        seen["deepest"] = max(seen["deepest"], len(python.reversals))
        seen["load warnings"] += bool(python.warning and "load" in python.warning)
        seen["reversals popped"] += len(python.reversals) < before
        if index % 97 == 0:
            assert same_doubles(c.state(), doubles_of(python.state())), index
        if index == restart:   # continue on fresh steppers from the saved states
            state, saved = python.state(), c.state()
            python = FeedforwardStepper(params, alpha=alpha, adapt_to_load=adapt, inverse=inverse)
            python.restore(state)
            from_c = CStepper(lib, cparams, params, alpha=alpha, adapt_to_load=adapt,
                              inverse=inverse)
            from_c.restore(saved)
            from_python = CStepper(lib, cparams, params, alpha=alpha, adapt_to_load=adapt,
                                   inverse=inverse)
            from_python.restore(doubles_of(state))
            c = from_c
    print(f"seed {seed} {inverse}: {STEPS} steps, largest |C - Python| P_ff "
          f"{worst['P_ff']:.3g} W, T_ref {worst['T_ref']:.3g} K; {seen}")
    assert worst == {"P_ff": 0.0, "T_ref": 0.0}
    assert seen["saturated"] > 0 and seen["load warnings"] > 0
    if inverse == "minor-loop":
        assert seen["deepest"] == depth and seen["reversals popped"] > 0


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
        assert normalized(refusal(lambda: c.initial_outputs(reference, load))) == normalized(message)
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
    for doubles in (saved[:6], saved + [0.0], saved[:-1], saved[:6] + [0.5] + saved[7:],
                    saved[:6] + [-1.0] + saved[7:]):
        assert "compensator state" in refusal(lambda: c.restore(doubles)) \
            or "reversals must be" in refusal(lambda: c.restore(doubles))
        assert same_doubles(c.state(), saved)
    for sample in walk[600:]:
        compare_step(python, c, sample, worst)
    assert worst == {"P_ff": 0.0, "T_ref": 0.0}
