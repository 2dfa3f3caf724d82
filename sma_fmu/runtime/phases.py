"""Phase fractions and the observables they determine (spec section 2).

    xi_P + xi_M + xi_F = 1
    R = R_P xi_P + R_M xi_M + R_F xi_F            [ohm]
    x = l_P xi_P + l_M xi_M + l_F xi_F            [m]
    S_C = -N k_B sum(xi ln xi)                    [J/K], 0 ln 0 = 0
"""
import math
from collections import namedtuple

from .constants import BOLTZMANN

__all__ = ["PhaseFractions", "resistance_of", "length_of", "configurational_entropy"]

PhaseFractions = namedtuple("PhaseFractions", ["xi_P", "xi_M", "xi_F"])
PhaseFractions.__doc__ = "Fractions of the lattice in the P, M and F phases [1]; they sum to 1."


def resistance_of(fractions, params):
    """Wire resistance [ohm] of the phase fractions (``params``: :class:`WireParameters`)."""
    xi_p, xi_m, xi_f = fractions
    return params.R_P * xi_p + params.R_M * xi_m + params.R_F * xi_f


def length_of(fractions, params):
    """Wire length [m] of the phase fractions."""
    xi_p, xi_m, xi_f = fractions
    return params.l_P * xi_p + params.l_M * xi_m + params.l_F * xi_f


def configurational_entropy(fractions, n_cells):
    """Configurational entropy S_C [J/K] of ``n_cells`` lattice cells mixed in these fractions."""
    # added left to right, not with sum(): from Python 3.12 sum() of floats compensates
    # (Neumaier), and the FMU's result would depend on its host's Python
    total = 0.0
    for xi in fractions:
        if xi > 0.0:
            total += xi * math.log(xi)
    return -n_cells * BOLTZMANN * total
