"""Both FMU families built from a parameter file with every issue-36 term on (nu_h != nu_c, a
second stage, thermal expansion, the stress law): the terms travel into each family
(resources/parameters.json, the native FMUs' compiled-in defaults), the plant and the
compensator of the two families agree bit for bit on walks in both hysteresis modes and both
inverses, and both equal the library steppers of that file."""
import random

import pytest

from native_twins import Instance
from sma_fmu.files.package_data import default_parameter_file
from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.reachable_band import reachable_band
from sma_fmu.wire.parameter_file import load_parameters

pytestmark = pytest.mark.needs("gcc")

SECTIONS = '''[second_stage]
w2    = { value = 0.13, unit = "1",       meaning = "share of M in stage 2" }
a2_h  = { value = 95.0, unit = "degC",    meaning = "stage-2 heating centre" }
b2_h  = { value = 80.0, unit = "degC/kg", meaning = "its rise per kg" }
a2_c  = { value = 70.0, unit = "degC",    meaning = "stage-2 cooling centre" }
b2_c  = { value = 45.0, unit = "degC/kg", meaning = "its rise per kg" }
nu2_h = { value = 45.0, unit = "1",       meaning = "stage-2 domain size heating" }
nu2_c = { value = 35.0, unit = "1",       meaning = "stage-2 domain size cooling" }

[strain]
alpha_P        = { value = 1.4e-5, unit = "1/K",  meaning = "expansion of P" }
alpha_MF       = { value = 6.6e-6, unit = "1/K",  meaning = "expansion of M and F" }
T_alpha        = { value = 22.0,   unit = "degC", meaning = "reference temperature" }
span_ratio_0   = { value = 0.9,    unit = "1",    meaning = "s at no stress" }
span_ratio_sat = { value = 1.12,   unit = "1",    meaning = "s at high stress" }
span_stress    = { value = 120.0,  unit = "MPa",  meaning = "stress scale" }

[constant_temperature]'''
NU = ('nu       = { value = 130.0,  unit = "1",  meaning = "cells per cooperative domain (both '
      'directions unless nu_h, nu_c are given): the larger, the narrower the transition (10-90 % '
      'over 2 ln 9 k_B tau_K^2/dH)" }')


@pytest.fixture(scope="module")
def terms_file(tmp_path_factory):
    text = default_parameter_file().read_text(encoding="utf-8")
    assert NU in text and "[constant_temperature]" in text
    text = text.replace(NU, NU + '\nnu_h = { value = 150.0, unit = "1", meaning = "heating" }'
                        '\nnu_c = { value = 105.0, unit = "1", meaning = "cooling" }')
    text = text.replace("[constant_temperature]", SECTIONS, 1)
    path = tmp_path_factory.mktemp("terms") / "terms.toml"
    path.write_text(text, encoding="utf-8")
    params = load_parameters(path)
    assert params.terms.two_stage and params.terms.strain and params.terms.nu_h != params.terms.nu_c
    return path


@pytest.fixture(scope="module")
def families(tmp_path_factory, terms_file):
    from sma_fmu.fmi.packaging.build import build_fmus
    from sma_fmu.fmi.packaging.c_family_build import build_native_fmus
    root = tmp_path_factory.mktemp("families_terms")
    names = ["SmaActuator", "SmaFeedforward"]
    return {"py": build_fmus(root / "py", terms_file, names=names),
            "nat": build_native_fmus(root / "nat", terms_file, names=names)}


def _pair(families, model, tag, start):
    sides = [Instance(families[family][model], f"{tag}-{family}") for family in ("py", "nat")]
    for side in sides:
        assert side.start(start) == 0, side.log[-2:]
    return sides


@pytest.mark.parametrize("mode", [1, 2])
def test_the_plants_agree_bit_for_bit_and_equal_the_library(families, terms_file, mode):
    params = load_parameters(terms_file)
    library = PlantStepper(params.replace(memory_depth=3),
                           mode={1: "continuous", 2: "switch"}[mode], load=0.2)
    py, nat = _pair(families, "SmaActuator", f"terms-plant{mode}",
                    {"hysteresis_mode": mode, "memory_depth": 3, "load": 0.2})
    rng, time, power, load = random.Random(mode), 0.0, 1.0, 0.2
    try:
        for k in range(6000):
            if k % rng.randint(40, 300) == 0:
                power = rng.choice([0.0, rng.uniform(0.0, 4.0)])
            if rng.random() < 0.003:
                load = rng.uniform(0.0, 0.4)
            for side in (py, nat):
                side.set("P_in", power)
                side.set("load", load)
                assert side.step(time, 1e-3) <= 1, side.log[-2:]
            time += 1e-3
            expected = library.step(power, load, 1e-3)
            a, b = py.values(), nat.values()
            assert a == b, (k, a, b)
            assert (a["R"], a["T"], a["x"]) == (expected.R, expected.T, expected.x), k
    finally:
        py.close()
        nat.close()


@pytest.mark.parametrize("inverse", [1, 2])
def test_the_compensators_agree_bit_for_bit_and_equal_the_library(families, terms_file,
                                                                  inverse):
    params = load_parameters(terms_file)
    band = reachable_band(0.1, params)
    library = FeedforwardStepper(params.replace(memory_depth=3),
                                 inverse={1: "major", 2: "minor-loop"}[inverse])
    library.initial_outputs(band.cold, 0.1)
    py, nat = _pair(families, "SmaFeedforward", f"terms-ff{inverse}",
                    {"inverse": inverse, "memory_depth": 3, "R_ref": band.cold, "load": 0.1})
    rng, time, reference, target, inside = random.Random(inverse), 0.0, band.cold, band.cold, 0
    try:
        for k in range(5000):
            if k % rng.randint(30, 250) == 0:
                target = rng.uniform(band.hot, band.cold)
            reference += 0.02 * (target - reference)
            for side in (py, nat):
                side.set("R_ref", reference)
                assert side.step(time, 1e-3) <= 1, side.log[-2:]
            time += 1e-3
            expected = library.step(reference, 0.1, 1e-3)
            a, b = py.values(), nat.values()
            assert a == b, (k, a, b)
            assert (a["P_ff"], a["T_ref"]) == (expected.P_ff, expected.T_ref), k
            inside += not expected.saturated
        assert inside > 2500
    finally:
        py.close()
        nat.close()
