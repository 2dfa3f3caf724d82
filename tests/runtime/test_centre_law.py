"""Centres whose load slope follows the transformation strain (Clausius-Clapeyron:
hysteresis.cc_share_h, cc_share_c; runtime/model_terms.centre_load).

Independent references: the centre shift integrated numerically from dT/dsigma =
eps_tr(sigma)/ds (scipy's solve_ivp and quad, not the closed form); the slope by central
differences; omitted or zero shares give main's linear centres a_d + b_d f bit for bit (the
formula written out here), and the plant and the compensator run exactly as without them; the
inverse (sensing) inverts the same centres; a bad share is refused naming file, key, value."""
import math
import random

import pytest
from scipy import integrate

from sma_fmu.runtime.constant_load import (branch_constants, constant_load_resistance,
                                           hysteresis_centre, second_centre)
from sma_fmu.runtime.constants import COOLING, HEATING, STANDARD_GRAVITY
from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.model_terms import centre_load, stress_ratio
from sma_fmu.runtime.parameters import ParameterError
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.sensing import sense_temperature
from sma_fmu.files.package_data import default_parameter_file
from sma_fmu.wire.parameter_file import load_parameter_set, load_parameters, write_parameter_file

# the NiTiHf set's stress law (s0 ~ 0.1 at saturation 1, 300 MPa) and a second stage
LAW = dict(span_ratio_0=0.1, span_ratio_sat=1.0, span_stress=300.0, cc_share_h=1.0,
           cc_share_c=0.6)
STAGE2 = dict(w2=0.3, a2_h=95.0, b2_h=60.0, a2_c=70.0, b2_c=40.0, nu2_h=60.0, nu2_c=50.0)


def _stress_per_kg(params):
    """d sigma / d f [MPa/kg] of the wire."""
    return STANDARD_GRAVITY / (math.pi * params.diameter ** 2 / 4.0) / 1e6


@pytest.mark.parametrize("share", [1.0, 0.6, 0.25])
def test_the_centre_shift_is_the_clausius_clapeyron_integral(params, share):
    """dT/dsigma = eps_tr(sigma)/ds with eps_tr = H [1 - c + c s(sigma)/s_sat] (H the
    saturated transformation strain, ds [MPa/K] the entropy per volume), integrated by
    solve_ivp over the stress: tau(f) - a equals it with b = (dsigma/df) H/ds."""
    wire = params.replace(**dict(LAW, cc_share_h=share))
    terms = wire.terms
    H, ds = 0.035, 0.26                 # [1], [MPa/K]: 0.135 K/MPa where s is saturated
    k = _stress_per_kg(wire)
    wire = wire.replace(b_h=k * H / ds)

    def slope(sigma, _):                # dT/dsigma [K/MPa]
        s = terms.span_ratio_sat + (terms.span_ratio_0 - terms.span_ratio_sat) * math.exp(
            -sigma / terms.span_stress)
        return [H * (1.0 - share + share * s / terms.span_ratio_sat) / ds]
    for load in (0.0, 0.01, 0.09, 0.36, 0.72, 1.08, 3.0):
        sigma = k * load
        shift = integrate.solve_ivp(slope, (0.0, sigma), [0.0], rtol=1e-12, atol=1e-12).y[0, -1] \
            if sigma > 0 else 0.0
        assert hysteresis_centre(load, HEATING, wire) - wire.a_h == pytest.approx(
            shift, rel=1e-9, abs=1e-9), load


def test_the_slope_follows_the_transformation_strain(params):
    """d tau_d/df = b_d [1 - c_d + c_d s(sigma)/s_sat] (central differences), and the
    strain-weighted load is the integral of that factor (quad)."""
    wire = params.replace(**LAW, **STAGE2)
    terms, h = wire.terms, 1e-6
    for load in (0.02, 0.2, 0.5, 1.0):
        s = stress_ratio(load, terms) / terms.span_ratio_sat
        for direction, share, b, b2 in ((HEATING, terms.cc_share_h, wire.b_h, terms.b2_h),
                                        (COOLING, terms.cc_share_c, wire.b_c, terms.b2_c)):
            factor = 1.0 - share + share * s
            for centre, slope in ((hysteresis_centre, b), (second_centre, b2)):
                numeric = (centre(load + h, direction, wire)
                           - centre(load - h, direction, wire)) / (2 * h)
                assert numeric == pytest.approx(slope * factor, rel=1e-6)
            integral = integrate.quad(lambda u: 1.0 - share + share * stress_ratio(
                u, terms) / terms.span_ratio_sat, 0.0, load, epsabs=1e-14, epsrel=1e-13)[0]
            assert centre_load(load, share, terms) == pytest.approx(integral, rel=1e-12)


def test_without_a_stress_law_or_share_the_centres_stay_linear_bit_for_bit(params):
    """Main's centres a_d + b_d f, written out: omitted shares, shares of 0 beside a stress
    law, and full shares without a stress law (s constant) all give them to the last bit."""
    rng = random.Random(5)
    cases = [params, params.replace(**dict(LAW, cc_share_h=0.0, cc_share_c=0.0), **STAGE2),
             params.replace(cc_share_h=1.0, cc_share_c=0.7)]
    for wire in cases:
        for _ in range(300):
            load = rng.choice([0.0, 0.05, rng.uniform(0.0, 1.0)])
            assert hysteresis_centre(load, HEATING, wire) == wire.a_h + wire.b_h * load
            assert hysteresis_centre(load, COOLING, wire) == wire.a_c + wire.b_c * load
            if wire.terms.two_stage:
                terms = wire.terms
                assert second_centre(load, HEATING, wire) == terms.a2_h + terms.b2_h * load
                assert second_centre(load, COOLING, wire) == terms.a2_c + terms.b2_c * load


def _runs(params, seed):
    """Plant outputs over power/load steps and compensator outputs over a reference walk."""
    rng, plant, rows = random.Random(seed), PlantStepper(params), []
    load = 0.0
    for step in range(2000):
        if step % 250 == 0:
            load = rng.choice([0.0, 0.05, 0.15, 0.25])
        rows.append(tuple(plant.step(rng.choice([0.0, 0.3, 1.0, 2.5, 4.0]), load, 0.01)))
    compensator = FeedforwardStepper(params, inverse="minor-loop")
    for step in range(2000):
        rows.append(tuple(compensator.step(41.85 + 6.05 * math.cos(math.pi * step * 1e-3)
                                           + rng.gauss(0.0, 0.5), 0.05 * (step // 700), 1e-3)))
    return rows


def test_zero_shares_change_no_run(params):
    """Shares given as 0 (with a stress law that would bend the centres were they on): the
    plant and the compensator run as without them, bit for bit; shares on change them."""
    law_only = params.replace(**dict(LAW, cc_share_h=0.0, cc_share_c=0.0))
    without = params.replace(span_ratio_0=0.1, span_ratio_sat=1.0, span_stress=300.0)
    assert _runs(law_only, 3) == _runs(without, 3)
    assert _runs(params.replace(**LAW), 3) != _runs(without, 3)


def test_sensing_inverts_the_same_centres(params):
    """sense(R(T)) = T on major branches with the law on (one and two stages): the inverse
    takes its centres from the same branch constants as the plant."""
    for wire in (params.replace(**LAW), params.replace(**LAW, **STAGE2)):
        for load in (0.0, 0.1, 0.3):
            for direction in (HEATING, COOLING):
                centre = branch_constants(load, direction, wire).centre
                for offset in (-6.0, -2.0, 0.0, 3.0, 7.0):
                    T = centre + offset
                    R = constant_load_resistance(T, load, direction, wire)
                    sensed = sense_temperature(R, load, direction, wire)
                    assert sensed.temperature == pytest.approx(T, abs=1e-8)


def test_the_law_moves_the_centre_where_the_strain_has_not_saturated(params):
    """With s0 = 0.1 and c = 1 the heating centre at 0.1 kg rises far less than b_h f (the
    slope there is about s b_h), and approaches the line's slope where s has saturated."""
    wire = params.replace(**LAW)
    rise = hysteresis_centre(0.1, HEATING, wire) - wire.a_h
    assert 0.1 * wire.b_h * 0.1 < rise < 0.5 * wire.b_h * 0.1
    far = hysteresis_centre(8.0, HEATING, wire) - hysteresis_centre(7.0, HEATING, wire)
    assert far == pytest.approx(wire.b_h, rel=1e-3)


GOOD = """
[strain]
span_ratio_0 = { value = 0.1, unit = "1", meaning = "s at no stress" }
span_stress  = { value = 300.0, unit = "MPa", meaning = "stress scale" }
"""
SHARES = """cc_share_h = { value = 1.0, unit = "1", meaning = "heating slope follows s" }
cc_share_c = { value = 0.6, unit = "1", meaning = "cooling slope follows s" }
"""


def _write(tmp_path, shares):
    text = default_parameter_file().read_text(encoding="utf-8")
    text = text.replace("[hysteresis]\n", "[hysteresis]\n" + shares, 1)
    path = tmp_path / "law.toml"
    path.write_text(text + GOOD, encoding="utf-8")
    return path


def test_a_file_with_the_law_loads_and_round_trips(tmp_path):
    loaded = load_parameter_set(_write(tmp_path, SHARES))
    assert (loaded.params.cc_share_h, loaded.params.cc_share_c) == (1.0, 0.6)
    again = load_parameter_set(write_parameter_file(tmp_path / "again.toml", loaded.params, "x"))
    assert again.params == loaded.params
    assert again.params.terms.cc_share_c == 0.6


@pytest.mark.parametrize("value, match", [
    ("1.5", r"hysteresis\.cc_share_h = 1\.5 must be in \[0, 1\]"),
    ("-0.1", r"hysteresis\.cc_share_h = -0\.1 must be in \[0, 1\]"),
    ("nan", r"hysteresis\.cc_share_h = nan must be a finite number in \[0, 1\]"),
])
def test_a_bad_share_is_refused_naming_file_key_and_value(tmp_path, value, match):
    path = _write(tmp_path, SHARES.replace("value = 1.0", f"value = {value}", 1))
    with pytest.raises(ParameterError, match=match) as caught:
        load_parameters(path)
    assert str(path) in str(caught.value)
