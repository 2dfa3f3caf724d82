"""Constant-length relation between load and temperature (spec section 8, paper eqs. 40-42).

    (df/dT)_x = (dS_C/dxi_F)_T / (g x_f),   dS_C/dxi_F = -N k_B (ln xi_F - ln(xi_P)/2 - ln(xi_M)/2)

on the loading path dxi_P = dxi_M = -dxi_F/2; the sign follows the paper (dW = f dx is
work done by the wire).
"""
import math

from .checks import require_finite
from .constants import BOLTZMANN, STANDARD_GRAVITY

__all__ = ["FRACTION_SUM_TOLERANCE", "entropy_gradient_F", "load_temperature_slope"]

FRACTION_SUM_TOLERANCE = 1e-3  # the paper's measured fractions sum to 1.0001


def _checked_fractions(xi_p, xi_m, xi_f):
    values = {"xi_P": xi_p, "xi_M": xi_m, "xi_F": xi_f}
    for name, value in values.items():
        value = require_finite(name, value)
        if not 0.0 < value < 1.0:
            raise ValueError(f"{name} must be in (0, 1), got {value!r}")
    total = xi_p + xi_m + xi_f
    if abs(total - 1.0) > FRACTION_SUM_TOLERANCE:
        raise ValueError(
            f"xi_P + xi_M + xi_F must be 1 within {FRACTION_SUM_TOLERANCE}, got {total!r}")
    return float(xi_p), float(xi_m), float(xi_f)


def entropy_gradient_F(xi_p, xi_m, xi_f, n_cells):
    """(dS_C/dxi_F)_T [J/K] along the loading path, for ``n_cells`` lattice cells."""
    xi_p, xi_m, xi_f = _checked_fractions(xi_p, xi_m, xi_f)
    return -n_cells * BOLTZMANN * (
        math.log(xi_f) - 0.5 * math.log(xi_p) - 0.5 * math.log(xi_m))


def load_temperature_slope(xi_p, xi_m, xi_f, params):
    """(df/dT)_x [kg/K]: load change per kelvin of a wire held at constant length."""
    return entropy_gradient_F(xi_p, xi_m, xi_f, params.N) / (STANDARD_GRAVITY * params.x_f)
