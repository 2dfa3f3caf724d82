"""The constant-load model (spec sections 2-4) along isobaric thermal cycles, vectorised.

On a major branch at load f and direction d (constants from
:func:`sma_fmu.runtime.constant_load.branch_constants`):

    q(T)  = xi_MF / M = 1 / (1 + e^Lambda),   Lambda = (dH(f)/k_B)(1/tau_K - 1/T_K)
    x(T)  = l_P + xi_Fmin (l_F - l_P) + M q(T) ((l_M + l_F)/2 - l_P)          [m]
    R(T)  = R_P + xi_Fmin (R_F - R_P) + M q(T) ((R_M + R_F)/2 - R_P)          [ohm]
    eps(T) = x(T) / L_ref - 1                                                 [1]

The hot length (q = 0) is l_P + xi_Fmin (l_F - l_P), the cold length (q = 1)
(l_M + l_F)/2 + xi_Fmin (l_F - l_M)/2. :func:`tangent_closed_form` gives the tangent-line
transformation temperatures of one branch from these formulas: the tangent at the
steepest point (q = 1/2 + T_K k_B/dH, solved with scipy's brentq) meets the two flat
ends (the model has no thermal expansion, so its baselines are horizontal).
"""
import numpy as np
from scipy import optimize, special

from sma_fmu.runtime.constant_load import branch_constants
from sma_fmu.runtime.constants import HEATING, KELVIN_OFFSET

__all__ = ["branch_share", "BranchLevels", "branch_levels", "model_strain", "model_resistance",
           "tangent_closed_form"]


def branch_share(temperature, constants):
    """q = xi_MF/M [1] on a major branch at ``temperature`` [degC] (array), from expit."""
    exponent = constants.energy_over_kB * (
        constants.inv_centre_K - 1.0 / (np.asarray(temperature, dtype=float) + KELVIN_OFFSET))
    return special.expit(-exponent)


class BranchLevels:
    """Hot value and span of strain [1] and resistance [ohm] on one branch (cold = hot + span)."""

    __slots__ = ("constants", "strain_hot", "strain_span", "resistance_hot", "resistance_span")

    def __init__(self, constants, strain_hot, strain_span, resistance_hot, resistance_span):
        self.constants = constants
        self.strain_hot, self.strain_span = strain_hot, strain_span
        self.resistance_hot, self.resistance_span = resistance_hot, resistance_span


def branch_levels(load, direction, params, reference_length):
    """:class:`BranchLevels` of the major branch at ``load`` [kg], ``direction`` (+1/-1).

    ``reference_length`` [m] is the length the strain is measured from.
    """
    c = branch_constants(load, direction, params)
    length_hot = params.l_P + c.xi_F_min * (params.l_F - params.l_P)
    length_span = c.M * (0.5 * (params.l_M + params.l_F) - params.l_P)
    resistance_hot = params.R_P + c.xi_F_min * (params.R_F - params.R_P)
    resistance_span = c.M * (params.R_MF - params.R_P)
    return BranchLevels(c, length_hot / reference_length - 1.0, length_span / reference_length,
                        resistance_hot, resistance_span)


def model_strain(temperature, load, direction, params, reference_length):
    """Strain [1] relative to ``reference_length`` [m] on the major branch at ``temperature`` [degC]."""
    levels = branch_levels(load, direction, params, reference_length)
    return levels.strain_hot + levels.strain_span * branch_share(temperature, levels.constants)


def model_resistance(temperature, load, direction, params):
    """Resistance [ohm] on the major branch at ``temperature`` [degC] (array)."""
    levels = branch_levels(load, direction, params, 1.0)
    return levels.resistance_hot + levels.resistance_span * branch_share(temperature, levels.constants)


def tangent_closed_form(load, direction, params, reference_length):
    """Tangent-line temperatures [degC] and levels of one major branch of the model.

    Returns {"start", "finish", "midpoint", "steepest", "slope", "strain_hot", "strain_cold"}:
    heating starts where the tangent meets the cold (martensite) level (A_s) and finishes at
    the hot level (A_f); cooling starts at the hot level (M_s) and finishes at the cold (M_f).
    ``midpoint`` is where the tangent crosses half way between the levels; ``slope`` [1/K].
    """
    levels = branch_levels(load, direction, params, reference_length)
    c = levels.constants
    energy = c.energy_over_kB
    tau = c.centre

    def condition(t):  # zero where d2 eps/dT2 = 0: q = 1/2 + T_K k_B/dH
        return branch_share(t, c) - 0.5 - (t + KELVIN_OFFSET) / energy

    width = 40.0 * (tau + KELVIN_OFFSET) ** 2 / energy
    steepest = optimize.brentq(condition, tau - width, tau + width, xtol=1e-12)
    q = float(branch_share(steepest, c))
    slope = -levels.strain_span * q * (1.0 - q) * energy / (steepest + KELVIN_OFFSET) ** 2
    at = levels.strain_hot + levels.strain_span * q
    hot = steepest + (levels.strain_hot - at) / slope
    cold = steepest + (levels.strain_hot + levels.strain_span - at) / slope
    middle = steepest + (levels.strain_hot + 0.5 * levels.strain_span - at) / slope
    start, finish = (cold, hot) if direction == HEATING else (hot, cold)
    return {"start": start, "finish": finish, "midpoint": middle, "steepest": steepest,
            "slope": slope, "strain_hot": levels.strain_hot,
            "strain_cold": levels.strain_hot + levels.strain_span}
