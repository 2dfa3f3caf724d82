"""The fit's vectorised model (identification/isobaric/terms.py) is the runtime's: with every
issue-36 term on, its strain on both major branches equals the plant runtime's length, and
with the terms off it is today's model."""
import numpy as np
import pytest

from sma_fmu.identification.isobaric.predict import drive_plant
from sma_fmu.identification.isobaric.model import model_strain
from sma_fmu.identification.isobaric.terms import branch_curve, span_ratio
from sma_fmu.runtime.constant_load import constant_load_fractions
from sma_fmu.runtime.phases import resistance_of

LOAD = 0.2     # kg


def _all_terms(params):
    return params.replace(nu_h=150.0, nu_c=110.0, w2=0.35, a2_h=80.0, b2_h=40.0, a2_c=58.0,
                          b2_c=70.0, nu2_h=45.0, nu2_c=60.0, alpha_P=1.1e-5, alpha_MF=-4e-5,
                          T_alpha=25.0, span_ratio_0=0.4, span_ratio_sat=1.1, span_stress=150.0)


def test_the_fit_model_is_the_plant_runtime_with_every_term_on(params):
    wire = _all_terms(params)
    assert wire.terms.two_stage and wire.terms.strain
    # up to where both stages have finished: the cooling branch from there is the major one
    up = np.linspace(10.0, 450.0, 2201)
    path = np.concatenate([up, up[::-1][1:]])
    length, deviation = drive_plant(wire, path, LOAD)
    assert deviation < 1e-9
    plant = length / wire.x0 - 1.0
    heating, _, _ = branch_curve(up, LOAD, 1, wire, wire.x0)
    cooling, _, _ = branch_curve(up[::-1][1:], LOAD, -1, wire, wire.x0)
    np.testing.assert_allclose(plant, np.concatenate([heating, cooling]), rtol=0, atol=1e-9)
    assert np.ptp(heating) > 0.01 and np.abs(heating[:-1] - cooling[::-1]).max() > 1e-3


def test_the_resistance_and_fractions_are_the_runtime_s(params):
    wire = _all_terms(params)
    for direction in (1, -1):
        temperatures = np.linspace(20.0, 150.0, 27)
        _, resistance, q = branch_curve(temperatures, LOAD, direction, wire, wire.x0)
        for t, r, share in zip(temperatures, resistance, q):
            fractions = constant_load_fractions(float(t), LOAD, direction, wire)
            assert r == pytest.approx(resistance_of(fractions, wire), rel=1e-12)
            assert share * (1 - fractions.xi_F + fractions.xi_M) == pytest.approx(
                2 * fractions.xi_M, abs=1e-12)


def test_with_the_terms_off_it_is_today_s_model(params):
    temperatures = np.linspace(20.0, 120.0, 41)
    for direction in (1, -1):
        strain, _, _ = branch_curve(temperatures, 0.12, direction, params, 0.8)
        np.testing.assert_allclose(strain, model_strain(temperatures, 0.12, direction, params, 0.8),
                                   rtol=0, atol=1e-15)
    assert span_ratio(0.3, params) == 1.0
