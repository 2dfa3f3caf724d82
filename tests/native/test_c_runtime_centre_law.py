"""The C runtime equals the Python runtime bit for bit with the Clausius-Clapeyron centres on
(hysteresis.cc_share_h, cc_share_c with the stress law and a second stage): the centre
functions on random loads and shares, the plant on random power/load walks in both
hysteresis modes, the compensator (major and minor-loop inverse) on random reference walks,
sense_temperature, and the refusal of a share outside [0, 1] (the same message)."""
import ctypes
import random

import pytest

from sma_fmu.runtime.constant_load import hysteresis_centre, second_centre
from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.model_terms import centre_load
from sma_fmu.runtime.parameters import WireParameters
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.sensing import sense_temperature

import c_feedforward
import c_plant
from c_plant import CPlant, doubles_of, normalized, power_of, power_walk, refusal, same
from c_runtime import load_with_signatures

# the NiTiHf fit's stress law and shares (s0 ~ 0.1, 300 MPa), a second stage, widths
LAW = dict(nu_h=150.0, nu_c=105.0, w2=0.3, a2_h=95.0, b2_h=60.0, a2_c=70.0, b2_c=40.0,
           nu2_h=60.0, nu2_c=50.0, span_ratio_0=0.1, span_ratio_sat=1.0, span_stress=300.0,
           cc_share_h=0.98, cc_share_c=0.63)

SHIM = r"""
#include <stdlib.h>
#include "constant_load.h"

void *law_params(const double *values) {
    SmaMessage m; WireParameters *p = malloc(sizeof *p);
    if (wire_parameters_from_values(p, values, &m)) { free(p); return NULL; }
    return p;
}
void law_free(void *p) { free(p); }
double law_centre(const void *p, double load, int direction) {
    return hysteresis_centre(load, direction, p);
}
double law_second(const void *p, double load, int direction) {
    return second_centre(load, direction, p);
}
double law_load(const void *p, double load, double share) {
    return centre_load(load, share, &((const WireParameters *)p)->terms);
}
"""
P, D, I = ctypes.c_void_p, ctypes.c_double, ctypes.c_int
SIGNATURES = {"law_params": (P, [ctypes.POINTER(D)]), "law_free": (None, [P]),
              "law_centre": (D, [P, D, I]), "law_second": (D, [P, D, I]),
              "law_load": (D, [P, D, D])}


@pytest.fixture(scope="module")
def law_params(params):
    changed = params.replace(**LAW)
    assert changed.terms.cc_share_h and changed.terms.two_stage and changed.terms.strain
    return changed


@pytest.fixture(scope="module")
def centre_lib(tmp_path_factory):
    return load_with_signatures(("sma_message", "checks", "lattice", "thermal", "phases",
                                 "constant_load", "minor_loops", "validity", "parameters"),
                                tmp_path_factory.mktemp("c_centre_law"), SHIM, SIGNATURES)


@pytest.fixture(scope="module")
def plant_lib(tmp_path_factory):
    return c_plant.load_library(tmp_path_factory.mktemp("c_plant_law"))


@pytest.fixture(scope="module")
def ff_lib(tmp_path_factory):
    return c_feedforward.load_library(tmp_path_factory.mktemp("c_ff_law"))


def test_the_centres_equal_python_bit_for_bit(centre_lib, law_params):
    rng = random.Random(11)
    for trial in range(40):
        wire = law_params.replace(cc_share_h=rng.choice([0.0, 1.0, rng.random()]),
                                  cc_share_c=rng.choice([0.0, 1.0, rng.random()]),
                                  span_ratio_0=rng.uniform(0.05, 2.0),
                                  span_stress=rng.uniform(20.0, 900.0))
        pointer = centre_lib.law_params(c_plant.c_values(wire.values()))
        assert pointer
        try:
            for _ in range(100):
                load = rng.choice([0.0, 1e-12, 0.05, rng.uniform(0.0, 1.2), rng.uniform(0, 30)])
                share = rng.random()
                assert centre_lib.law_load(pointer, load, share) == centre_load(
                    load, share, wire.terms)
                for direction in (1, -1):
                    assert centre_lib.law_centre(pointer, load, direction) == \
                        hysteresis_centre(load, direction, wire)
                    assert centre_lib.law_second(pointer, load, direction) == \
                        second_centre(load, direction, wire)
        finally:
            centre_lib.law_free(pointer)


@pytest.mark.parametrize("seed, mode, depth, load", [(41, "continuous", 64, 0.0),
                                                     (42, "switch", 64, 0.2),
                                                     (43, "continuous", 5, 0.45)])
def test_the_c_plant_equals_python_with_the_law_on(plant_lib, law_params, seed, mode, depth,
                                                   load):
    params = law_params.replace(memory_depth=depth)
    rng = random.Random(seed)
    python = PlantStepper(params, None, mode, load)
    c = CPlant(plant_lib, params, None, mode, load)
    assert same(c.outputs, tuple(python.outputs))
    for index, instruction in enumerate(power_walk(rng, params, 3000)):
        sample = power_of(instruction, python)
        expected, got = python.step(*sample), c.step(*sample)
        assert same(got, tuple(expected)), (index, sample, got, expected)
        assert c.warning == python.warning, sample
        if index % 300 == 0:
            assert same(c.state(), doubles_of(python.state())), index


@pytest.mark.parametrize("seed, inverse, adapt", [(51, "major", True), (52, "minor-loop", True),
                                                  (53, "minor-loop", False)])
def test_the_c_compensator_equals_python_with_the_law_on(ff_lib, law_params, seed, inverse,
                                                         adapt):
    rng = random.Random(seed)
    cparams = c_feedforward.CParameters(ff_lib, law_params)
    python = FeedforwardStepper(law_params, adapt_to_load=adapt, inverse=inverse)
    c = c_feedforward.CStepper(ff_lib, cparams, law_params, adapt_to_load=adapt, inverse=inverse)
    walk = c_feedforward.reference_walk(rng, law_params, 3000)
    inside = 0
    for index, sample in enumerate(walk):
        expected, got = python.step(*sample), c.step(*sample)
        assert got == tuple(expected), (index, sample, got, expected)
        inside += not expected.saturated
    assert inside > 500      # the inverse ran, not only the clamp


def test_sense_temperature_equals_python_with_the_law_on(ff_lib, law_params):
    cparams = c_feedforward.CParameters(ff_lib, law_params)
    rng = random.Random(12)
    temperature, saturated = ctypes.c_double(), ctypes.c_int()
    error = ctypes.create_string_buffer(512)
    empty = (ctypes.c_double * 1)()
    for _ in range(1500):
        load, direction = rng.choice([0.0, 0.1, rng.uniform(0.0, 0.5)]), rng.choice((1, -1))
        resistance = rng.uniform(33.0, 51.0)
        expected = sense_temperature(resistance, load, direction, law_params)
        assert ff_lib.sense(cparams.pointer, resistance, load, direction, empty, 0,
                            ctypes.byref(temperature), ctypes.byref(saturated), error) == 0
        assert (temperature.value, bool(saturated.value)) == tuple(expected)


@pytest.mark.parametrize("changes", [{"cc_share_h": 1.0000001}, {"cc_share_c": -1e-9},
                                     {"cc_share_c": float("inf")}])
def test_a_bad_share_is_refused_alike(plant_lib, params, changes):
    values = {**params.values(), **changes}
    source = "SmaActuator instance 'law'"
    with pytest.raises(ValueError) as caught:
        WireParameters.from_values(values, source=source)
    message = str(caught.value)
    assert sorted(changes)[0] in message and "in [0, 1]" in message
    assert normalized(refusal(lambda: c_plant.CParameters(plant_lib, values, source))) == \
        normalized(message)
