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

import pytest

from sma_fmu.runtime.parameters import PARAMETER_SPECS, WireParameters
from sma_fmu.runtime.plant import PlantStepper

from c_plant import (OUTPUTS, RUNTIME, CParameters, CPlant, doubles_of, load_library,
                     normalized, power_of, power_walk, refusal, same, state_of)
from c_runtime import compile_win64


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    return load_library(tmp_path_factory.mktemp("c_plant"))


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
           "margin": (0.0, 0.5), "depth": (1.0, 2.5, 100001.0, math.inf),
           "share": (1.0000001, -1e-9, math.inf, math.nan)}
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


def test_the_major_branch_entropy_and_direction_names_equal_python(lib, params):
    """constant_load_resistance, configurational_entropy, direction_sign of a name and
    check_format, which the plant does not call, against Python (refusals alike)."""
    from sma_fmu.runtime.checks import direction_sign
    from sma_fmu.runtime.plant import STATE_FORMAT
    from sma_fmu.runtime.state_entries import check_format
    from sma_fmu.runtime.constant_load import constant_load_fractions, constant_load_resistance
    from sma_fmu.runtime.phases import configurational_entropy
    cparams, rng = CParameters(lib, params.values()), random.Random(5)
    out, error = ctypes.c_double(), ctypes.create_string_buffer(512)
    for _ in range(3000):
        temperature = rng.choice([rng.uniform(-100.0, 300.0), -273.15, -300.0, math.nan])
        load = rng.choice([rng.uniform(0.0, 1.0), 0.0, -0.5, 1.7e308, math.inf])
        direction = rng.choice((1, -1))
        try:
            expected = constant_load_resistance(temperature, load, direction, params)
        except ValueError as refused:
            assert lib.load_resistance(cparams.pointer, temperature, load, direction, out, error)
            assert normalized(error.value.decode()) == normalized(str(refused))
            continue
        assert not lib.load_resistance(cparams.pointer, temperature, load, direction, out, error)
        assert repr(out.value) == repr(expected)
        fractions = constant_load_fractions(temperature, load, direction, params)
        assert repr(lib.entropy(*fractions, params.N)) == repr(
            configurational_entropy(fractions, params.N))
    assert repr(lib.entropy(1.0, 0.0, 0.0, params.N)) == repr(
        configurational_entropy((1.0, 0.0, 0.0), params.N))
    sign = ctypes.c_int()
    for text in ("heating", " Cooling ", "HEATING", "heat", "", "50%s%n"):
        try:
            expected = direction_sign(text)
        except ValueError as refused:
            assert lib.direction_of_text(text.encode(), ctypes.byref(sign), error)
            assert normalized(error.value.decode()) == normalized(str(refused))
            continue
        assert not lib.direction_of_text(text.encode(), ctypes.byref(sign), error)
        assert sign.value == expected
    for found in (STATE_FORMAT, "sma-fmu plant state 1", None):
        try:
            check_format({"format": found}, STATE_FORMAT, "plant state")
        except ValueError as refused:
            assert lib.format_check(None if found is None else found.encode(), error)
            assert error.value.decode() == str(refused)
            continue
        assert not lib.format_check(found.encode(), error)
