"""The C plant (sma_fmu/fmi/c_family/runtime/plant.c) equals the Python PlantStepper.

Both are driven side by side on long random power/load walks (nested reversals, wiped-out
loops, a memory of 4 points that overflows and one of 64, load changes, loads and
temperatures past the validity limits, several step sizes, both hysteresis modes, several
T_start). Every output must be bit-for-bit equal at every step: the C code does the same
operations in the same order and is compiled with -ffp-contract=off, and CPython's math
calls the same libm. Saved states, bad inputs, bad states and bad parameters must be
refused alike, with messages equal up to how numbers are printed (C prints %.17g).
"""
import ctypes
import math
import random
import re

import pytest

from sma_fmu.runtime.parameters import PARAMETER_SPECS, WireParameters
from sma_fmu.runtime.plant import STATE_FORMAT, PlantStepper

from c_runtime import compile_runtime, compile_win64

RUNTIME = ("sma_message", "checks", "state_entries", "lattice", "thermal", "phases",
           "constant_load", "minor_loops", "validity", "parameters", "plant")
OUTPUTS = ("R", "T", "x", "xi_P", "xi_M", "xi_F", "P", "heating")

# a test-only front over the C API: objects on the heap, errors and warnings as text
SHIM = r"""
#include <stdlib.h>
#include <string.h>
#include "plant.h"

static void copy_error(char *error, const SmaMessage *m) { memcpy(error, m->text, 512); }
void *params_new(const double *values, const char *source, char *error) {
    SmaMessage m; WireParameters *p = malloc(sizeof *p);
    if (wire_parameters_from_values_source(p, values, source, &m)) {
        copy_error(error, &m); free(p); return NULL;
    }
    return p;
}
void params_free(void *p) { free(p); }
void *plant_new(const void *params, int has_start, double start, const char *mode,
                double load, char *error) {
    SmaMessage m; PlantStepper *s = malloc(sizeof *s);
    if (plant_stepper_init(s, params, has_start ? &start : NULL, mode, load, &m)) {
        copy_error(error, &m); free(s); return NULL;
    }
    return s;
}
void plant_delete(void *s) { plant_stepper_free(s); free(s); }
void plant_outputs(const void *stepper, double *out, char *warning) {
    const PlantStepper *s = stepper; const PlantOutputs *o = &s->outputs;
    out[0] = o->R; out[1] = o->T; out[2] = o->x; out[3] = o->xi_P; out[4] = o->xi_M;
    out[5] = o->xi_F; out[6] = o->P; out[7] = o->heating;
    memcpy(warning, s->warning, sizeof s->warning);
}
int plant_step(void *s, double power, double load, double h, char *error) {
    SmaMessage m;
    if (plant_stepper_step(s, power, load, h, &m)) { copy_error(error, &m); return 1; }
    return 0;
}
size_t plant_size(const void *s) { return plant_stepper_state_size(s); }
void plant_write(const void *s, double *out) { plant_stepper_state_write(s, out); }
int plant_read(void *s, const double *in, size_t count, char *error) {
    SmaMessage m;
    if (plant_stepper_state_read(s, in, count, &m)) { copy_error(error, &m); return 1; }
    return 0;
}
"""

D, P, I, S, C = (ctypes.c_double, ctypes.c_void_p, ctypes.c_int, ctypes.c_size_t,
                 ctypes.c_char_p)
DP = ctypes.POINTER(ctypes.c_double)
SIGNATURES = {
    "params_new": (P, [DP, C, C]), "params_free": (None, [P]),
    "plant_new": (P, [P, I, D, C, D, C]), "plant_delete": (None, [P]),
    "plant_outputs": (None, [P, DP, C]), "plant_step": (I, [P, D, D, D, C]),
    "plant_size": (S, [P]), "plant_write": (None, [P, DP]), "plant_read": (I, [P, DP, S, C]),
}


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    library = compile_runtime(RUNTIME, tmp_path_factory.mktemp("c_plant"), extra_source=SHIM)
    for name, (restype, argtypes) in SIGNATURES.items():
        function = getattr(library, name)
        function.restype, function.argtypes = restype, argtypes
    return library


def c_values(values):
    """A name -> value mapping as the C values[] array (PARAMETER_SPECS order, None = NaN)."""
    numbers = [values.get(spec.name) for spec in PARAMETER_SPECS]
    return (ctypes.c_double * len(numbers))(*[math.nan if v is None else float(v)
                                             for v in numbers])


class CParameters:
    """WireParameters in C; a refusal raises ValueError with the C message."""

    def __init__(self, lib, values, source="<parameters>"):
        error = ctypes.create_string_buffer(512)
        self.lib, self.pointer = lib, lib.params_new(c_values(values), source.encode(), error)
        if not self.pointer:
            raise ValueError(error.value.decode())

    def __del__(self):
        if getattr(self, "pointer", None):
            self.lib.params_free(self.pointer)


class CPlant:
    """The C PlantStepper with Python's method names; refusals raise ValueError."""

    def __init__(self, lib, params, T_start=None, mode="continuous", load=0.0):
        self.lib, self.cparams = lib, CParameters(lib, params.values())
        error = ctypes.create_string_buffer(512)
        self.pointer = lib.plant_new(self.cparams.pointer, T_start is not None,
                                     0.0 if T_start is None else T_start,
                                     None if mode is None else mode.encode(), load, error)
        if not self.pointer:
            raise ValueError(error.value.decode())
        self._read()

    def __del__(self):
        if getattr(self, "pointer", None):
            self.lib.plant_delete(self.pointer)

    def _read(self):
        out, warning = (ctypes.c_double * 8)(), ctypes.create_string_buffer(256)
        self.lib.plant_outputs(self.pointer, out, warning)
        self.warning = warning.value.decode() or None
        return tuple(out[:7]) + (bool(out[7]),)

    @property
    def outputs(self):
        return self._read()

    def step(self, power, load, step_size):
        error = ctypes.create_string_buffer(512)
        if self.lib.plant_step(self.pointer, power, load, step_size, error):
            raise ValueError(error.value.decode())
        return self._read()

    def state(self):
        out = (ctypes.c_double * self.lib.plant_size(self.pointer))()
        self.lib.plant_write(self.pointer, out)
        return list(out)

    def restore(self, values):
        error = ctypes.create_string_buffer(512)
        array = (ctypes.c_double * max(len(values), 1))(*values)
        if self.lib.plant_read(self.pointer, array, len(values), error):
            raise ValueError(error.value.decode())


def doubles_of(state):
    """Python's state() dict in the C layout (plant.h)."""
    out = [float(state[key]) for key in ("temperature", "direction", "load", "xi_MF", "xi_P",
                                         "power")]
    out.append(float(len(state["reversals"])))
    for temperature, xi_mf in state["reversals"]:
        out += [float(temperature), float(xi_mf)]
    return out


def state_of(values):
    """The C layout as Python's state() dict."""
    count = int(values[6])
    return {"format": STATE_FORMAT, "temperature": values[0], "direction": int(values[1]),
            "load": values[2], "xi_MF": values[3], "xi_P": values[4], "power": values[5],
            "reversals": [[values[7 + 2 * i], values[8 + 2 * i]] for i in range(count)]}


def same(a, b):
    """Bit-for-bit equal sequences (repr tells -0.0 from 0.0 and round-trips exactly)."""
    return len(a) == len(b) and all(repr(x) == repr(y) for x, y in zip(a, b))


_NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+(?:\.\d*)?(?:[eE][-+]?\d+)?|inf|nan)(?![\w.])")


def normalized(text):
    """A message with every number as Python's repr of its float ('-1' and '-1.0' agree)."""
    return _NUMBER.sub(lambda match: repr(abs(float(match.group())))
                       if match.group().lstrip("+-") == "nan" else repr(float(match.group())),
                       text)


def refusal(call):
    """The message of the ValueError ``call`` raises."""
    with pytest.raises(ValueError) as caught:
        call()
    return str(caught.value)


# ---------------------------------------------------------------- the walks

def power_walk(rng, params, steps):
    """Instructions (kind, value, load [kg], h [s]): kind "T" asks for the power that takes
    the Python plant to that temperature [degC] in one step, "P" is a power [W]. Nested
    reversals of shrinking amplitude, returns to exact earlier levels, noise (many tiny
    loops), excursions past validity.T_max, load changes (some past load_max, some every
    step), zero and negative power, several step sizes."""
    load, h = rng.choice([0.0, 0.05, 0.15]), rng.choice([0.01, 0.02, 0.05])
    history, plan = [], []
    if rng.random() < 0.5:                     # held power: T may stay put (direction kept)
        plan += [("P", 0.0, load, h)] * rng.randint(1, 4)
    while len(plan) < steps:
        kind = rng.random()
        if kind < 0.35:                        # nested reversals of shrinking amplitude
            deep = rng.random() < 0.1          # sometimes deeper than a memory of 64
            centre, amplitude = rng.uniform(35.0, 130.0), rng.uniform(3.0, 50.0)
            sign = rng.choice((1, -1))
            for _ in range(rng.randint(60, 90) if deep else rng.randint(2, 14)):
                goal = centre + sign * amplitude
                plan += [("T", goal, load, h)] * rng.randint(1, 3)
                history.append(goal)
                amplitude *= rng.uniform(0.95, 0.98) if deep else rng.uniform(0.4, 0.95)
                sign = -sign
        elif kind < 0.45 and history:          # back exactly to earlier levels
            for _ in range(rng.randint(1, 5)):
                plan += [("T", rng.choice(history), load, h)] * rng.randint(1, 3)
        elif kind < 0.55:                      # powers as they come: 0, negative, ramps
            for _ in range(rng.randint(1, 30)):
                plan.append(("P", rng.choice([0.0, -1.0, rng.uniform(0.0, 6.0),
                                              rng.uniform(-2.0, 8.0)]), load, h))
        elif kind < 0.6:                       # past validity.T_max and back
            plan += [("T", params.T_max + rng.uniform(-5.0, 40.0), load, h)] * rng.randint(1, 4)
        elif kind < 0.72:                      # a load change (sometimes past load_max)
            load = rng.choice([0.0, 0.02, 0.05, 0.1, 0.25, 0.5, rng.uniform(0.0, 0.3),
                               params.load_max * rng.uniform(1.0, 1.5)])
        elif kind < 0.8:                       # a load that changes every step
            for _ in range(rng.randint(5, 90)):
                load = abs(load + rng.gauss(0.0, 0.02))
                plan.append(("T", rng.uniform(30.0, 140.0), load, h))
        elif kind < 0.85:                      # another step size
            h = rng.choice([0.01, 0.02, 0.05, 1e-3, rng.uniform(1e-4, 0.2)])
        else:                                  # noise around the last level: tiny loops
            level = history[-1] if history else rng.uniform(40.0, 120.0)
            plan += [("T", level + rng.gauss(0.0, 0.5), load, h)
                     for _ in range(rng.randint(2, 40))]
    return plan[:steps]


def power_of(instruction, python):
    kind, value, load, h = instruction
    if kind == "P":
        return value, load, h
    from sma_fmu.runtime.thermal import power_to_reach, step_decay
    params = python.params
    decay = step_decay(h, params.tau_th)
    return power_to_reach(python.temperature, value, params.T_room, params.K_th, decay), load, h


class Tally:
    """The largest |C - Python| per output, the steps compared and what the walks reached."""

    def __init__(self):
        self.worst = dict.fromkeys(OUTPUTS, 0.0)
        self.steps = self.warnings = self.full = self.shrank = self.deepest = 0


TALLY = Tally()


def compare(python, c, sample):
    """One step through both; every output and the warning must be equal."""
    expected = python.step(*sample)
    got = c.step(*sample)
    for name, a, b in zip(OUTPUTS, got, expected):
        TALLY.worst[name] = max(TALLY.worst[name], abs(float(a) - float(b)))
    assert same(got, tuple(expected)), (sample, got, expected)
    assert c.warning == python.warning, sample
    TALLY.steps += 1
    TALLY.warnings += python.warning is not None
    return expected


CASES = [  # (seed, mode, memory_depth, T_start, initial load)
    (1, "continuous", 64, None, 0.0),
    (2, "continuous", 4, None, 0.05),
    (3, "switch", 64, None, 0.1),
    (4, "continuous", 4, 120.0, 0.0),
    (5, "switch", 4, 35.0, 0.6),
    (6, "continuous", 2, 310.0, 0.05),
    (7, "continuous", 64, 60.0, 0.25),
    (8, "continuous", 6, -20.0, 0.0),
]
STEPS = 6000


@pytest.mark.parametrize("seed, mode, depth, T_start, load", CASES)
def test_the_c_plant_equals_the_python_one(lib, params, seed, mode, depth, T_start, load):
    params = params.replace(memory_depth=depth)
    rng = random.Random(seed)
    python = PlantStepper(params, T_start, mode, load)
    c = CPlant(lib, params, T_start, mode, load)
    assert same(c.outputs, tuple(python.outputs)) and c.warning == python.warning
    plan = power_walk(rng, params, STEPS)
    others = []                                # (Python, C) pairs restored mid-walk
    full = 0
    for index, instruction in enumerate(plan):
        sample = power_of(instruction, python)
        before = len(python.reversals)
        compare(python, c, sample)
        for other_python, other_c in others:
            compare(other_python, other_c, sample)
        full += len(python.reversals) == depth
        TALLY.full += len(python.reversals) == depth
        TALLY.shrank += len(python.reversals) < before
        TALLY.deepest = max(TALLY.deepest, len(python.reversals))
        if index % 250 == 0:
            assert same(c.state(), doubles_of(python.state()))
        if index == STEPS // 2:                # C's state into C and Python, Python's into C
            restored_c, crossed_c = CPlant(lib, params, mode=mode), CPlant(lib, params, mode=mode)
            restored_python = PlantStepper(params, mode=mode)
            restored_c.restore(c.state())
            crossed_c.restore(doubles_of(python.state()))
            restored_python.restore(state_of(c.state()))
            for other in (restored_c, crossed_c):
                assert same(other.outputs, tuple(python.outputs))
            others = [(restored_python, restored_c), (PlantStepper(params, mode=mode), crossed_c)]
            others[1][0].restore(python.state())
    if mode == "continuous":
        assert full > 0                        # the memory filled up and dropped points
    print(f"\nplant walks so far: {TALLY.steps} steps compared, {TALLY.warnings} warnings, "
          f"{TALLY.shrank} steps that shrank the stack, {TALLY.full} with a full memory, "
          f"deepest stack {TALLY.deepest}; largest "
          f"|C - Python| per output: {TALLY.worst}")
    assert all(value == 0.0 for value in TALLY.worst.values())



# ---------------------------------------------------------------- refusals

def walked_pair(lib, params, steps=300, seed=11):
    """A Python and a C plant (memory of 6) walked alike to a state with a reversal stack."""
    params = params.replace(memory_depth=6)
    python, c = PlantStepper(params), CPlant(lib, params)
    plan = power_walk(random.Random(seed), params, steps)
    for instruction in plan:
        compare(python, c, power_of(instruction, python))
    assert python.reversals
    return python, c, params


@pytest.mark.parametrize("power, load, step_size", [
    (math.nan, 0.05, 0.02), (math.inf, 0.05, 0.02), (-math.inf, 0.05, 0.02),
    (1.0, -1.0, 0.02), (1.0, math.nan, 0.02), (1.0, math.inf, 0.02), (1.0, 1.7e308, 0.02),
    (1.0, 0.05, 0.0), (1.0, 0.05, -0.02), (1.0, 0.05, math.nan), (1.0, 0.05, math.inf),
    (1.7e308, 0.05, 0.02),
])
def test_bad_inputs_are_refused_alike_and_change_nothing(lib, params, power, load, step_size):
    python, c, _ = walked_pair(lib, params)
    before = c.state()
    message = refusal(lambda: python.step(power, load, step_size))
    assert normalized(refusal(lambda: c.step(power, load, step_size))) == normalized(message)
    assert same(c.state(), before) and same(c.state(), doubles_of(python.state()))
    for instruction in power_walk(random.Random(12), python.params, 300):
        compare(python, c, power_of(instruction, python))


def test_bad_arguments_at_the_start_are_refused_alike(lib, params):
    for T_start, mode, load in ((math.nan, "continuous", 0.0), (-273.15, "continuous", 0.0),
                                (-300.0, "switch", 0.0), (math.inf, "switch", 0.0),
                                (None, "Continuous", 0.0), (None, "50%s%n", 0.0),
                                (None, None, 0.0), (None, "switch", -1.0),
                                (None, "switch", math.nan), (None, "continuous", 1.7e308)):
        message = refusal(lambda: PlantStepper(params, T_start, mode, load))
        got = refusal(lambda: CPlant(lib, params, T_start, mode, load))
        assert normalized(got) == normalized(message), (T_start, mode, load)


def _bad_states(state, params):
    """(a Python state dict, its C doubles, what both messages name)."""
    def changed(**entries):
        new = {**state, **entries}
        return new, doubles_of(new)
    point = list(state["reversals"][0])
    yield changed(temperature=math.nan) + ("temperature",)
    yield changed(temperature=-273.15) + ("temperature",)
    yield changed(temperature=-300.0) + ("temperature",)
    yield changed(temperature=params.T_max + 1.0) + ("temperature",)
    yield changed(direction=0) + ("direction",)
    yield changed(direction=2) + ("direction",)
    yield changed(direction=0.5) + ("direction",)
    yield changed(load=-0.1) + ("load",)
    yield changed(load=math.inf) + ("load",)
    yield changed(load=1.7e308) + ("state entry load:",)
    yield changed(xi_MF=-0.1) + ("xi_MF",)
    yield changed(xi_MF=1.5) + ("xi_MF",)
    yield changed(xi_P=math.nan) + ("xi_P",)
    yield changed(xi_MF=state["xi_MF"] * 0.5) + ("xi_MF = ",)
    yield changed(power=-1.0) + ("power",)
    yield changed(power=math.inf) + ("power",)
    yield changed(reversals=state["reversals"] + [[-274.0, 0.5]]) + ("reversals[",)
    yield changed(reversals=[[point[0], 1.5]] + state["reversals"][1:]) + ("reversals[0]",)
    yield changed(reversals=[[math.inf, 0.5]]) + ("reversals[0]",)
    yield changed(reversals=[[math.nan, 0.5]]) + ("reversals[0]",)


def test_bad_states_are_refused_alike_and_change_nothing(lib, params):
    python, c, params = walked_pair(lib, params)
    state = python.state()
    before = c.state()
    cases = list(_bad_states(state, params))
    for bad_state, values, name in cases:
        message = refusal(lambda: PlantStepper(params).restore(bad_state))
        got = refusal(lambda: c.restore(values))
        assert name in got and normalized(got) == normalized(message), (name, got, message)
        assert same(c.state(), before)
    # too many points: Python prints the list, C the count; both name "reversals must be"
    values = doubles_of({**state, "reversals": [list(state["reversals"][0])] * 7})
    message = refusal(lambda: PlantStepper(params).restore(state_of(values)))
    got = refusal(lambda: c.restore(values))
    assert got.split(" got ")[0] == message.split(" got ")[0] and same(c.state(), before)
    # C's own layout: too short, a count that is not a whole number or does not fit
    for values, name in ((before[:6], "plant state"), (before[:7] + [1.0], "reversals"),
                         (before[:6] + [0.5], "reversals"), (before[:6] + [-2.0], "reversals"),
                         (before + [20.0], "reversals"), (before[:-2], "reversals")):
        assert name in refusal(lambda: c.restore(values))
        assert same(c.state(), before)
    for instruction in power_walk(random.Random(13), params, 300):
        compare(python, c, power_of(instruction, python))


def _bad_parameters(values):
    """Parameter sets both must refuse: each rule broken, derived constants out of range,
    the consistency checks."""
    bad = {"positive": (0.0, -1.0, math.inf, math.nan), "nonnegative": (-1e-9, math.inf),
           "fraction": (1.0, -0.1, math.nan), "finite": (math.inf, -math.inf, math.nan),
           "margin": (0.0, 0.5), "depth": (1.0, 2.5, 100001.0, math.inf)}
    for spec in PARAMETER_SPECS:
        for value in bad[spec.rule]:
            if spec.required or not math.isnan(value):   # C: NaN = an optional one not given
                yield {**values, spec.name: value}
    yield {**values, "diameter": 1e200}                     # diameter**2 overflows
    yield {**values, "h_c": 1e-200, "A_s": 1e-200}          # 1/(h_c A_s): division by zero
    yield {**values, "mass": 1e-320, "x0": 1e10}            # line density underflows to 0
    yield {**values, "x0": 1e300, "mass": 1e300}            # lattice: N overflows
    yield {**values, "nu": 1e300, "eps_T": 1e300}           # nu eps_T / k_B overflows
    yield {**values, "stress_max": 1e306}                   # load_max overflows
    yield {**values, "R_M": 20.0, "R_F": 20.0}              # R_MF <= R_P
    yield {**values, "l_F": 0.7}                            # x_f <= 0
    yield {**values, "T_room": -300.0}
    yield {**values, "T_max": values["T_room"]}


def test_bad_parameters_are_refused_alike(lib, params):
    values = params.values()
    count = 0
    for bad in _bad_parameters(values):
        for source in ("<parameters>", "SmaActuator instance 'a%s'"):
            message = refusal(lambda: WireParameters.from_values(bad, source=source))
            got = refusal(lambda: CParameters(lib, bad, source))
            assert normalized(got) == normalized(message), (bad, got, message)
            count += 1
    assert count > 100


def test_good_parameters_derive_the_same_constants(lib, params):
    """alpha given or not, memory_depth and stress_max given or defaulted: the C plant made
    from them runs like the Python one (so the derived constants are the same)."""
    values = params.values()
    for changes in ({}, {"alpha": 0.3}, {"memory_depth": 2}, {"stress_max": 150.0},
                    {"diameter": 2e-4, "mass": 1.2e-4, "T_room": 25.0}):
        changed = params.replace(**changes)
        python, c = PlantStepper(changed, mode="continuous", load=0.3), CPlant(lib, changed,
                                                                              load=0.3)
        assert same(c.outputs, tuple(python.outputs)) and c.warning == python.warning
        for instruction in power_walk(random.Random(len(changes)), changed, 500):
            compare(python, c, power_of(instruction, python))
    defaults = {k: v for k, v in values.items() if k not in ("memory_depth", "stress_max")}
    python = PlantStepper(WireParameters.from_values(defaults), load=0.6)
    c = CPlant(lib, WireParameters.from_values(defaults), load=0.6)
    assert c.warning == python.warning is not None


def test_the_runtime_compiles_clean_for_win64(tmp_path):
    """x86_64-w64-mingw32-gcc -std=c99 -Wall -Wextra -Wpedantic -Werror -ffp-contract=off."""
    objects = compile_win64(RUNTIME, tmp_path)
    if objects is None:
        pytest.skip("x86_64-w64-mingw32-gcc is not installed")
    assert all(path.stat().st_size > 0 for path in objects)
