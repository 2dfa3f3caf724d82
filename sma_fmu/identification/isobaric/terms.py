"""The issue-36 model terms (DESIGN-36.md), vectorised for the isobaric fit.

Optional wire-file terms, each with a default that gives today's model:

- ``nu_h``, ``nu_c`` [1]: domain size on heating / cooling (default ``nu``);
- a second stage: share ``w2`` [1] of the transformable fraction M, centres
  ``tau2_d = a2_d + b2_d f`` [degC, degC/kg], domain sizes ``nu2_h``, ``nu2_c`` [1]
  (``w2 = 0``: off);
- thermal expansion ``alpha_P``, ``alpha_MF`` [1/K] about ``T_alpha`` [degC];
- the stress law of the transformation strain, s(sigma) = span_ratio_sat +
  (span_ratio_0 - span_ratio_sat) exp(-sigma/span_stress) [1], sigma [MPa];
- centres whose load slope follows it (Clausius-Clapeyron), ``cc_share_h``, ``cc_share_c``
  [1]: tau_d = a_d + b_d f_d with f_d of :func:`slope_load` (0: f_d = f, linear centres).

On a major branch of direction d at load f [kg] and temperature T [degC]:

    q_k = 1/(1 + e^Lambda_k),  Lambda_k = nu_k,d (eps_T - g f x_T/N)/k_B (1/tau_k,d,K - 1/T_K),
    tau_k,d = a_k,d + b_k,d f_d
    q   = (1 - w2) q1 + w2 q2,   xi_MF = M q,  xi_P = M (1 - q),  M = 1 - xi_Fmin(f)
    x   = l_P(T) xi_P + l_M(T, f) xi_MF/2 + l_F(T, f) (xi_Fmin + xi_MF/2)                  [m]
    l_P(T) = l_P (1 + alpha_P (T - T_alpha)),
    l_i(T, f) = [l_P + s(sigma) (l_i - l_P)] (1 + alpha_MF (T - T_alpha))   (i = M, F)
    R   = R_P xi_P + R_M xi_MF/2 + R_F (xi_Fmin + xi_MF/2)                                 [ohm]

The terms in use (defaults filled in) are the runtime's ``params.terms``
(:mod:`sma_fmu.runtime.model_terms`); tests/test_isobaric_terms.py checks this numpy version
against the runtime's plant with every term on.
"""
import math

import numpy as np
from scipy import special

from sma_fmu.runtime.constants import BOLTZMANN, HEATING, KELVIN_OFFSET, STANDARD_GRAVITY

__all__ = ["stress_MPa", "span_ratio", "slope_load", "branch_curve"]


def stress_MPa(load, diameter):
    """Tensile stress [MPa] of a hung mass ``load`` [kg] on a wire of ``diameter`` [m]."""
    return STANDARD_GRAVITY * np.asarray(load, dtype=float) / (math.pi * diameter ** 2 / 4.0) / 1e6


def span_ratio(load, params):
    """s(sigma) [1]: the factor on every phase's length deviation from l_P at ``load`` [kg]."""
    p = params.terms
    sigma = stress_MPa(load, params.diameter)
    return p.span_ratio_sat + (p.span_ratio_0 - p.span_ratio_sat) * np.exp(-sigma / p.span_stress)


def slope_load(load, direction, params):
    """f_d [kg]: the load the centres' slopes multiply in ``direction`` (+1/-1), as
    :func:`sma_fmu.runtime.constant_load.slope_load`: ``load`` [kg] itself when cc_share_d
    is 0, else f [1 + c_d (s_0/s_sat - 1) phi(sigma/span_stress)], phi(x) = (1 - e^-x)/x."""
    p = params.terms
    share = p.cc_share_h if direction == HEATING else p.cc_share_c
    if share == 0.0:
        return load
    x = np.asarray(stress_MPa(load, params.diameter) / p.span_stress)
    positive = x > 0.0
    phi = np.where(positive, -np.expm1(-x) / np.where(positive, x, 1.0), 1.0)
    return load * (1.0 + share * ((p.span_ratio_0 - p.span_ratio_sat) / p.span_ratio_sat) * phi)


def _share(temperature_K, load, per_nu, a, b, nu):
    """Logistic q of one stage (expit keeps both halves exact); ``load``: the slopes' f_d."""
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
    f_d = slope_load(load, direction, p)
    q = _share(temperature_K, f_d, per_nu, p.a_h if h else p.a_c, p.b_h if h else p.b_c,
               terms.nu_h if h else terms.nu_c)
    w2 = terms.w2
    if w2 != 0.0:
        q2 = _share(temperature_K, f_d, per_nu, terms.a2_h if h else terms.a2_c,
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
