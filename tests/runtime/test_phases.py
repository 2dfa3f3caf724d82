"""Fractions and observables (spec section 2): entropy, resistance, length."""
import math

import pytest

from sma_fmu.runtime.constant_length import entropy_gradient_F
from sma_fmu.runtime.constants import BOLTZMANN
from sma_fmu.runtime.phases import (PhaseFractions, configurational_entropy, length_of,
                                    resistance_of)


def test_entropy_closed_forms(params):
    n = params.N
    assert configurational_entropy(PhaseFractions(1.0, 0.0, 0.0), n) == 0.0  # 0 ln 0 = 0
    assert configurational_entropy(PhaseFractions(1 / 3, 1 / 3, 1 / 3), n) == pytest.approx(
        n * BOLTZMANN * math.log(3.0), rel=1e-14)


def test_entropy_gradient_is_the_derivative_along_the_loading_path(params):
    """Section 8's dS_C/dxi_F equals the numerical derivative of section 2's S_C
    along dxi_P = dxi_M = -dxi_F/2."""
    p, m, f, h = 0.4391, 0.2805, 0.2805, 1e-6
    s = lambda d: configurational_entropy(PhaseFractions(p - d / 2, m - d / 2, f + d), params.N)
    numerical = (s(h) - s(-h)) / (2 * h)
    assert numerical == pytest.approx(entropy_gradient_F(p, m, f, params.N), rel=1e-7)


def test_observables_are_the_expected_values_of_the_fractions(params):
    for phase, (r, x) in {0: (params.R_P, params.x_min), 1: (params.R_M, params.l_M),
                          2: (params.R_F, params.l_F)}.items():
        pure = PhaseFractions(*[1.0 if i == phase else 0.0 for i in range(3)])
        assert resistance_of(pure, params) == r
        assert length_of(pure, params) == x
    # the M/F mix at 50/50 has the mean resistance and the cold length x0
    half = PhaseFractions(0.0, 0.5, 0.5)
    assert resistance_of(half, params) == pytest.approx(params.R_MF, abs=1e-12)
    assert length_of(half, params) == pytest.approx(params.x0, abs=1e-12)
