"""The optional model terms (docs/model.md, 4a), vectorised for the isobaric fit.

Optional wire-file terms, each with a default that gives today's model:

- ``nu_h``, ``nu_c`` [1]: domain size on heating / cooling (default ``nu``);
- a second stage: share ``w2`` [1] of the transformable fraction M, centres
  ``tau2_d = a2_d + b2_d f`` [degC, degC/kg], domain sizes ``nu2_h``, ``nu2_c`` [1]
  (``w2 = 0``: off);
- thermal expansion ``alpha_P``, ``alpha_MF`` [1/K] about ``T_alpha`` [degC];
- the stress law of the transformation strain, s(sigma) = span_ratio_sat +
  (span_ratio_0 - span_ratio_sat) exp(-sigma/span_stress) [1], sigma [MPa].

On a major branch of direction d at load f [kg] and temperature T [degC]:

    q_k = 1/(1 + e^Lambda_k),  Lambda_k = nu_k,d (eps_T - g f x_T/N)/k_B (1/tau_k,d,K - 1/T_K)
    q   = (1 - w2) q1 + w2 q2,   xi_MF = M q,  xi_P = M (1 - q),  M = 1 - xi_Fmin(f)
    x   = l_P(T) xi_P + l_M(T, f) xi_MF/2 + l_F(T, f) (xi_Fmin + xi_MF/2)                  [m]
    l_P(T) = l_P (1 + alpha_P (T - T_alpha)),
    l_i(T, f) = [l_P + s(sigma) (l_i - l_P)] (1 + alpha_MF (T - T_alpha))   (i = M, F)
    R   = R_P xi_P + R_M xi_MF/2 + R_F (xi_Fmin + xi_MF/2)                                 [ohm]

The terms in use (defaults filled in) are the runtime's ``params.terms``
(:mod:`sma_fmu.runtime.model_terms`); tests/identification/test_isobaric_terms.py checks this
numpy version against the runtime's plant with every term on.
"""
import math

import numpy as np
from scipy import special

from sma_fmu.runtime.constants import BOLTZMANN, HEATING, KELVIN_OFFSET, STANDARD_GRAVITY

__all__ = ["stress_MPa", "span_ratio", "branch_curve"]


def stress_MPa(load, diameter):
    """Tensile stress [MPa] of a hung mass ``load`` [kg] on a wire of ``diameter`` [m]."""
    return STANDARD_GRAVITY * np.asarray(load, dtype=float) / (math.pi * diameter ** 2 / 4.0) / 1e6


def span_ratio(load, params):
    """s(sigma) [1]: the factor on every phase's length deviation from l_P at ``load`` [kg]."""
    p = params.terms
    sigma = stress_MPa(load, params.diameter)
    return p.span_ratio_sat + (p.span_ratio_0 - p.span_ratio_sat) * np.exp(-sigma / p.span_stress)


def _share(temperature_K, load, per_nu, a, b, nu):
    """Logistic q of one stage (expit keeps both halves exact)."""
    centre_K = a + b * load + KELVIN_OFFSET
    return special.expit(-(nu * per_nu) * (1.0 / centre_K - 1.0 / temperature_K))


def branch_curve(temperature, load, direction, params, reference_length):
    """(strain [1] relative to ``reference_length`` [m], resistance [ohm], q [1]) on the major
    branch of ``direction`` (+1/-1) at ``temperature`` [degC] and ``load`` [kg] (arrays or
    scalars, broadcast)."""
    p, terms = params, params.terms
    t = np.asarray(temperature, dtype=float)
    load = np.asarray(load, dtype=float)
    temperature_K = t + KELVIN_OFFSET
    per_nu = (p.eps_T - STANDARD_GRAVITY * load * p.x_T / p.N) / BOLTZMANN
    h = direction == HEATING
    q = _share(temperature_K, load, per_nu, p.a_h if h else p.a_c, p.b_h if h else p.b_c,
               terms.nu_h if h else terms.nu_c)
    w2 = terms.w2
    if w2 != 0.0:
        q2 = _share(temperature_K, load, per_nu, terms.a2_h if h else terms.a2_c,
                    terms.b2_h if h else terms.b2_c, terms.nu2_h if h else terms.nu2_c)
        q = (1.0 - w2) * q + w2 * q2
    xi_f_min = p.xi_F_inf * (1.0 - np.exp(-load / p.f_F))
    total = 1.0 - xi_f_min
    xi_mf = total * q
    xi_p = total - xi_mf
    s = span_ratio(load, p)
    l_p = p.l_P
    grow_p = 1.0 + terms.alpha_P * (t - terms.T_alpha)
    grow_mf = 1.0 + terms.alpha_MF * (t - terms.T_alpha)
    l_m = (l_p + s * (p.l_M - l_p)) * grow_mf
    l_f = (l_p + s * (p.l_F - l_p)) * grow_mf
    length = l_p * grow_p * xi_p + l_m * (0.5 * xi_mf) + l_f * (xi_f_min + 0.5 * xi_mf)
    resistance = p.R_P * xi_p + p.R_M * (0.5 * xi_mf) + p.R_F * (xi_f_min + 0.5 * xi_mf)
    return length / reference_length - 1.0, resistance, q
