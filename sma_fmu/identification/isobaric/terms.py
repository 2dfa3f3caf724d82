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
from collections import namedtuple

import numpy as np
from scipy import special

from sma_fmu.runtime.constants import BOLTZMANN, HEATING, KELVIN_OFFSET, STANDARD_GRAVITY

__all__ = ["stress_MPa", "span_ratio", "BranchScalars", "SCALARS", "Q_SCALARS", "branch_scalars",
           "curve", "curve_derivatives", "branch_curve"]


def stress_MPa(load, diameter):
    """Tensile stress [MPa] of a hung mass ``load`` [kg] on a wire of ``diameter`` [m]."""
    return STANDARD_GRAVITY * np.asarray(load, dtype=float) / (math.pi * diameter ** 2 / 4.0) / 1e6


def span_ratio(load, params):
    """s(sigma) [1]: the factor on every phase's length deviation from l_P at ``load`` [kg]."""
    p = params.terms
    sigma = stress_MPa(load, params.diameter)
    return p.span_ratio_sat + (p.span_ratio_0 - p.span_ratio_sat) * np.exp(-sigma / p.span_stress)


BranchScalars = namedtuple("BranchScalars", [
    "energy1", "centre1_K", "energy2", "centre2_K", "w2", "T_alpha", "hot0", "hot1", "span0",
    "span1", "resistance_hot", "resistance_span"])
BranchScalars.__doc__ = """What one major branch (a load, a direction) of the model rests on.

energy_k = nu_k,d (eps_T - g f x_T/N)/k_B [K] and centre_k = a_k,d + b_k,d f [K] of stage k
(stage 2: w2 = 0, energy2 = 0 when off); the length is x = hot(T) + span(T) q with
hot(T) = hot0 + hot1 (T - T_alpha) and span(T) = span0 + span1 (T - T_alpha) [m, m/K]; the
resistance resistance_hot + resistance_span q [ohm].
"""
SCALARS = BranchScalars._fields
Q_SCALARS = ("energy1", "centre1_K", "energy2", "centre2_K", "w2")   # the ones q depends on


def branch_scalars(params, load, direction):
    """:class:`BranchScalars` of the major branch of ``direction`` (+1/-1) at ``load`` [kg]."""
    p, terms = params, params.terms
    load = np.asarray(load, dtype=float)
    per_nu = (p.eps_T - STANDARD_GRAVITY * load * p.x_T / p.N) / BOLTZMANN
    h = direction == HEATING
    centre1 = (p.a_h if h else p.a_c) + (p.b_h if h else p.b_c) * load + KELVIN_OFFSET
    energy1 = (terms.nu_h if h else terms.nu_c) * per_nu
    w2 = terms.w2
    if terms.a2_h is not None and terms.a2_c is not None:   # the second stage, even at w2 = 0
        centre2 = (terms.a2_h if h else terms.a2_c) + (terms.b2_h if h else terms.b2_c) * load \
            + KELVIN_OFFSET
        energy2 = (terms.nu2_h if h else terms.nu2_c) * per_nu
    else:
        centre2, energy2 = centre1 * 0.0 + KELVIN_OFFSET, centre1 * 0.0
    xi_f_min = p.xi_F_inf * (1.0 - np.exp(-load / p.f_F))
    total = 1.0 - xi_f_min
    s = span_ratio(load, p)
    l_p = p.l_P
    l_m = l_p + s * (p.l_M - l_p)
    l_f = l_p + s * (p.l_F - l_p)
    mean = 0.5 * (l_m + l_f)
    return BranchScalars(
        energy1, centre1, energy2, centre2, w2, terms.T_alpha,
        hot0=l_p * total + l_f * xi_f_min,
        hot1=l_p * total * terms.alpha_P + l_f * xi_f_min * terms.alpha_MF,
        span0=total * (mean - l_p), span1=total * (mean * terms.alpha_MF - l_p * terms.alpha_P),
        resistance_hot=p.R_P * total + p.R_F * xi_f_min, resistance_span=total * (p.R_MF - p.R_P))


def _stage(temperature_K, energy, centre_K):
    """Logistic q of one stage (expit keeps both halves exact)."""
    return special.expit(-energy * (1.0 / centre_K - 1.0 / temperature_K))


def curve(temperature, scalars, reference_length):
    """(strain [1] relative to ``reference_length`` [m], resistance [ohm], q [1]) of the
    branch ``scalars`` (:func:`branch_scalars`) at ``temperature`` [degC]."""
    s = scalars
    t = np.asarray(temperature, dtype=float)
    temperature_K = t + KELVIN_OFFSET
    q = _stage(temperature_K, s.energy1, s.centre1_K)
    if s.w2 != 0.0:
        q = (1.0 - s.w2) * q + s.w2 * _stage(temperature_K, s.energy2, s.centre2_K)
    dt = t - s.T_alpha
    length = s.hot0 + s.hot1 * dt + (s.span0 + s.span1 * dt) * q
    return length / reference_length - 1.0, s.resistance_hot + s.resistance_span * q, q


def curve_derivatives(temperature, scalars, reference_length):
    """:func:`curve` at ``temperature`` [degC] (array) and its derivatives: {"strain",
    "resistance", "value_q": the values; "q": dq/d(each of
    Q_SCALARS) as columns, "dq_dT" [1/K], "strain_q": d strain/dq (q held), "strain_T":
    d strain/dT with q held [1/K], "strain_lengths": d strain/d(hot0, hot1, span0, span1)
    as columns, "resistance_q": d resistance/dq, "resistance_levels": d resistance/d
    (resistance_hot, resistance_span)}."""
    s = scalars
    t = np.asarray(temperature, dtype=float)
    temperature_K = t + KELVIN_OFFSET
    n = t.size
    dq = np.zeros((n, len(Q_SCALARS)))
    q = np.zeros(n)
    dq_dT = np.zeros(n)
    for k, (energy, centre, weight) in enumerate(((s.energy1, s.centre1_K, 1.0 - s.w2),
                                                  (s.energy2, s.centre2_K, s.w2))):
        if np.all(energy == 0.0):        # no second stage
            continue
        qk = _stage(temperature_K, energy, centre)
        slope = -qk * (1.0 - qk)            # dq_k / dLambda_k
        dq[:, 2 * k] = weight * slope * (1.0 / centre - 1.0 / temperature_K)
        dq[:, 2 * k + 1] = weight * slope * (-energy / centre ** 2)
        dq_dT += weight * slope * energy / temperature_K ** 2
        q += weight * qk
        dq[:, 4] += qk * (1.0 if k == 1 else -1.0)
    dt = t - s.T_alpha
    length = reference_length
    return {"q": dq, "dq_dT": dq_dT, "value_q": q,
            "strain": (s.hot0 + s.hot1 * dt + (s.span0 + s.span1 * dt) * q) / length - 1.0,
            "resistance": s.resistance_hot + s.resistance_span * q,
            "strain_q": (s.span0 + s.span1 * dt) / length,
            "strain_T": (s.hot1 + s.span1 * q) / length,
            "strain_lengths": np.column_stack([np.ones(n), dt, q, q * dt]) / length,
            "resistance_q": np.full(n, s.resistance_span),
            "resistance_levels": np.column_stack([np.ones(n), q])}


def branch_curve(temperature, load, direction, params, reference_length):
    """(strain [1] relative to ``reference_length`` [m], resistance [ohm], q [1]) on the major
    branch of ``direction`` (+1/-1) at ``temperature`` [degC] and ``load`` [kg] (arrays or
    scalars, broadcast)."""
    return curve(temperature, branch_scalars(params, load, direction), reference_length)
