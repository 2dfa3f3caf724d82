"""The C runtime equals the Python runtime bit for bit with every term of issue 36 switched on
(nu_h != nu_c, a second stage, thermal expansion and the stress law): the plant on random
power/load walks in both hysteresis modes, the compensator (major and minor-loop inverse)
on random reference walks, sense_temperature on random stacks, and the refusals of the new
parameters' rules (the same message, naming the key and the value)."""
import ctypes
import random

import pytest

from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.minor_loops import ReversalPoint
from sma_fmu.runtime.parameters import WireParameters
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.reachable_band import reachable_band
from sma_fmu.runtime.sensing import sense_temperature

import c_feedforward
import c_plant
from c_plant import CPlant, doubles_of, normalized, power_of, power_walk, refusal, same

# every new term on, values of the size the lab files show (issue 36)
TERMS = dict(nu_h=150.0, nu_c=105.0, w2=0.13, a2_h=95.0, b2_h=80.0, a2_c=70.0, b2_c=45.0,
             nu2_h=45.0, nu2_c=35.0, alpha_P=1.4e-5, alpha_MF=6.6e-6, T_alpha=22.0,
             span_ratio_0=0.9, span_ratio_sat=1.12, span_stress=120.0)


@pytest.fixture(scope="module")
def terms_params(params):
    changed = params.replace(**TERMS)
    assert changed.terms.two_stage and changed.terms.strain
    return changed


@pytest.fixture(scope="module")
def plant_lib(tmp_path_factory):
    return c_plant.load_library(tmp_path_factory.mktemp("c_plant_terms"))


@pytest.fixture(scope="module")
def ff_lib(tmp_path_factory):
    return c_feedforward.load_library(tmp_path_factory.mktemp("c_ff_terms"))


PLANT_CASES = [  # (seed, mode, memory_depth, T_start, initial load)
    (21, "continuous", 64, None, 0.0),
    (22, "switch", 64, None, 0.1),
    (23, "continuous", 4, 150.0, 0.25),
    (24, "switch", 6, 60.0, 0.6),
]
STEPS = 4000


@pytest.mark.parametrize("seed, mode, depth, T_start, load", PLANT_CASES)
def test_the_c_plant_equals_python_with_every_term_on(plant_lib, terms_params, seed, mode, depth,
                                                      T_start, load):
    params = terms_params.replace(memory_depth=depth)
    rng = random.Random(seed)
    python = PlantStepper(params, T_start, mode, load)
    c = CPlant(plant_lib, params, T_start, mode, load)
    assert same(c.outputs, tuple(python.outputs))
    reversals, restored = 0, False
    for index, instruction in enumerate(power_walk(rng, params, STEPS)):
        sample = power_of(instruction, python)
        before = len(python.reversals)
        expected, got = python.step(*sample), c.step(*sample)
        assert same(got, tuple(expected)), (index, sample, got, expected)
        assert c.warning == python.warning, sample
        reversals += len(python.reversals) != before
        if index % 200 == 0:
            assert same(c.state(), doubles_of(python.state())), index
        if (index >= STEPS // 2 and not restored
                and python.temperature <= params.T_max):   # a state restore() accepts
            restored = True            # go on from Python's saved state in a fresh C plant
            c = CPlant(plant_lib, params, mode=mode)
            c.restore(doubles_of(python.state()))
            assert same(c.outputs, tuple(python.outputs))
    assert restored
    if mode == "continuous":
        assert reversals > 50   # the minor-loop branches were exercised


def test_the_terms_change_the_plant(plant_lib, params, terms_params):
    """The walks above compare something the terms change: x and R differ from the paper's."""
    old, new = PlantStepper(params, load=0.2), PlantStepper(terms_params, load=0.2)
    differ = {"R": 0, "x": 0}
    for step in range(400):
        power = 1.5 if step < 200 else 0.0
        a, b = old.step(power, 0.2, 0.02), new.step(power, 0.2, 0.02)
        differ["R"] += abs(a.R - b.R) > 1e-6
        differ["x"] += abs(a.x - b.x) > 1e-9
    assert differ["R"] > 100 and differ["x"] > 300, differ


FF_CASES = [  # (seed, inverse, adapt_to_load, memory_depth)
    (31, "major", True, 64),
    (32, "minor-loop", True, 64),
    (33, "minor-loop", False, 6),
    (34, "major", False, 64),
]


@pytest.mark.parametrize("seed, inverse, adapt, depth", FF_CASES)
def test_the_c_compensator_equals_python_with_every_term_on(ff_lib, terms_params, seed, inverse,
                                                            adapt, depth):
    params = terms_params.replace(memory_depth=depth)
    rng = random.Random(seed)
    cparams = c_feedforward.CParameters(ff_lib, params)
    python = FeedforwardStepper(params, adapt_to_load=adapt, inverse=inverse)
    c = c_feedforward.CStepper(ff_lib, cparams, params, adapt_to_load=adapt, inverse=inverse)
    walk = c_feedforward.reference_walk(rng, params, STEPS)
    assert c.initial_outputs(*walk[0][:2]) == tuple(python.initial_outputs(*walk[0][:2]))
    inside = 0
    for index, sample in enumerate(walk):
        expected, got = python.step(*sample), c.step(*sample)
        assert got == tuple(expected), (index, sample, got, expected)
        warnings = [w if w is None else normalized(w) for w in (c.warning, python.warning)]
        assert warnings[0] == warnings[1], sample
        inside += not expected.saturated
        if index % 200 == 0:
            assert c_feedforward.same_doubles(
                c.state(), c_feedforward.doubles_of(python.state())), index
    assert inside > STEPS // 4   # the two-stage root solve ran, not only the clamp


def test_sense_temperature_equals_python_with_two_stages(ff_lib, terms_params):
    cparams = c_feedforward.CParameters(ff_lib, terms_params)
    rng = random.Random(9)
    temperature, saturated = ctypes.c_double(), ctypes.c_int()
    error = ctypes.create_string_buffer(512)
    for _ in range(2000):
        load = rng.choice([0.0, 0.05, 0.2, rng.uniform(0.0, 0.5)])
        points, level = [], rng.uniform(20.0, 120.0)
        for k in range(rng.randint(0, 8)):
            level += (-1) ** k * rng.uniform(0.0, 25.0)
            points.append(ReversalPoint(level, rng.uniform(0.0, 1.0)))
        direction = rng.choice((1, -1))
        resistance = rng.uniform(33.0, 51.0)
        expected = sense_temperature(resistance, load, direction, terms_params, points)
        flat = (ctypes.c_double * max(1, 2 * len(points)))(*[v for p in points for v in p])
        assert ff_lib.sense(cparams.pointer, resistance, load, direction, flat, len(points),
                            ctypes.byref(temperature), ctypes.byref(saturated), error) == 0
        assert (temperature.value, bool(saturated.value)) == tuple(expected)


BAD_TERMS = [
    {"w2": 1.0}, {"w2": -0.1}, {"nu_h": 0.0}, {"nu_c": -5.0}, {"nu2_h": 0.0},
    {"span_stress": 0.0}, {"span_ratio_0": -1.0}, {"alpha_P": float("inf")},
    {"a2_h": 60.0, "a2_c": 70.0},                         # heating centre below cooling
    {"w2": 0.1, "a2_c": 70.0}, {"w2": 0.1, "a2_h": 90.0},  # a centre missing
    {"w2": 0.2, "a2_h": 95.0, "a2_c": 70.0, "nu2_h": 1e307},  # dH2/k_B overflows
]


@pytest.mark.parametrize("changes", BAD_TERMS)
def test_bad_terms_are_refused_alike(plant_lib, params, changes):
    values = {**params.values(), **changes}
    source = "SmaActuator instance 'terms'"
    try:
        WireParameters.from_values(values, source=source)
    except ValueError as error:
        message = str(error)
        got = refusal(lambda: c_plant.CParameters(plant_lib, values, source))
        assert normalized(got) == normalized(message)
        key = sorted(changes)[0] if len(changes) == 1 else None
        if key is not None:
            assert key in message and message.startswith(source)
        return
    # accepted by both (dH2 overflow is found at the first branch): the first step refuses alike
    python = refusal(lambda: PlantStepper(WireParameters.from_values(values), load=0.0))
    c = refusal(lambda: CPlant(plant_lib, WireParameters.from_values(values), load=0.0))
    assert normalized(c) == normalized(python) and "dH(f) overflows" in python


def test_a_diverging_second_stage_inverse_is_refused_alike(ff_lib, terms_params):
    """A broad stage 2 (nu2 = 5) whose closed form leaves 1/T_K > 0 at the clamp: both refuse
    with the same message, naming the second stage."""
    params = terms_params.replace(nu2_h=5.0, nu2_c=5.0)
    cparams = c_feedforward.CParameters(ff_lib, params)
    temperature, saturated = ctypes.c_double(), ctypes.c_int()
    error = ctypes.create_string_buffer(512)
    empty = (ctypes.c_double * 1)()
    refused = 0
    for resistance in (33.0, 34.0, 40.0, 48.0, 50.0):
        try:
            expected = sense_temperature(resistance, 0.1, 1, params)
        except ValueError as caught:
            assert ff_lib.sense(cparams.pointer, resistance, 0.1, 1, empty, 0,
                                ctypes.byref(temperature), ctypes.byref(saturated), error) != 0
            assert normalized(error.value.decode()) == normalized(str(caught))
            assert "second stage" in str(caught)
            refused += 1
            continue
        assert ff_lib.sense(cparams.pointer, resistance, 0.1, 1, empty, 0,
                            ctypes.byref(temperature), ctypes.byref(saturated), error) == 0
        assert (temperature.value, bool(saturated.value)) == tuple(expected)
    assert refused > 0


def test_a_broad_second_stage_senses_and_refuses_alike(ff_lib, terms_params):
    """nu2 = 8: hot targets whose stage-2 closed form diverges (inverted from 1/T_K = 0) and
    targets no temperature reaches (refused): C and Python alike, bit for bit."""
    params = terms_params.replace(nu2_h=8.0, nu2_c=8.0, saturation_margin=1e-9)
    cparams = c_feedforward.CParameters(ff_lib, params)
    temperature, saturated = ctypes.c_double(), ctypes.c_int()
    error = ctypes.create_string_buffer(512)
    empty = (ctypes.c_double * 1)()
    rng, counts = random.Random(4), {"sensed": 0, "refused": 0}
    for _ in range(1500):
        load, direction = rng.choice([0.0, 0.05, 0.2]), rng.choice((1, -1))
        band = reachable_band(load, params)
        resistance = band.hot + (band.cold - band.hot) * 10.0 ** rng.uniform(-8.0, 0.0)
        got = ff_lib.sense(cparams.pointer, resistance, load, direction, empty, 0,
                           ctypes.byref(temperature), ctypes.byref(saturated), error)
        try:
            expected = sense_temperature(resistance, load, direction, params)
        except ValueError as caught:
            assert got != 0 and normalized(error.value.decode()) == normalized(str(caught))
            counts["refused"] += 1
            continue
        assert got == 0 and (temperature.value, bool(saturated.value)) == tuple(expected)
        counts["sensed"] += 1
    assert counts["sensed"] > 500 and counts["refused"] > 50, counts
