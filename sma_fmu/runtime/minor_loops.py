"""Minor loops without a jump at reversals: hysteresis mode "continuous" (spec section 6).

The paper switches branch with sgn(dT/dt), so R jumps at every reversal inside the
transformation. Here, after a reversal at (T_r, xi_r), with L_h, L_c the major branches:

    heating:  xi_MF(T) = xi_r L_h(T) / L_h(T_r)
    cooling:  xi_MF(T) = M - (M - xi_r)(M - L_c(T)) / (M - L_c(T_r))

The cooling form is evaluated through xi_P = M - xi_MF so neither end loses digits.
Where a denominator is below :data:`DENOMINATOR_FLOOR` the branch is flat: xi stays xi_r.
"""
from collections import namedtuple

from .constants import HEATING
from .constant_load import branch_fractions

__all__ = ["Reversal", "DENOMINATOR_FLOOR", "minor_branch_fractions", "major_equivalent"]

DENOMINATOR_FLOOR = 1e-12

Reversal = namedtuple("Reversal", ["temperature", "xi_MF"])
Reversal.__doc__ = "State before the step in which the direction changed: T_r [degC], xi_r [1]."


def _clamp(value, total):
    return 0.0 if value < 0.0 else (total if value > total else value)


def minor_branch_fractions(temperature, constants, direction, reversal):
    """(xi_MF, xi_P) [1] on the minor branch leaving ``reversal`` in ``direction``.

    ``constants`` are the :class:`BranchConstants` of the major branch of ``direction``
    at the present load; the result is clamped into [0, M] so a load change after the
    reversal cannot give negative fractions.
    """
    total = constants.M
    if direction == HEATING:
        at_reversal = branch_fractions(reversal.temperature, constants)[0]
        if at_reversal < DENOMINATOR_FLOOR:
            xi_mf = _clamp(reversal.xi_MF, total)
        else:
            xi_mf = _clamp(
                reversal.xi_MF * branch_fractions(temperature, constants)[0] / at_reversal, total)
        return xi_mf, total - xi_mf
    at_reversal = branch_fractions(reversal.temperature, constants)[1]
    if at_reversal < DENOMINATOR_FLOOR:
        xi_p = _clamp(total - reversal.xi_MF, total)
    else:
        xi_p = _clamp((total - reversal.xi_MF)
                      * branch_fractions(temperature, constants)[1] / at_reversal, total)
    return total - xi_p, xi_p


def major_equivalent(xi_mf, xi_p, constants, direction, reversal):
    """Map a point of a minor branch to the major-branch fractions at the same temperature.

    Returns (xi_MF, xi_P) of the major branch of ``direction``, or None where the minor
    branch is flat (denominator below the floor) and no temperature can be inferred.
    This is the closed-form inverse of :func:`minor_branch_fractions`.
    """
    total = constants.M
    if direction == HEATING:
        at_reversal = branch_fractions(reversal.temperature, constants)[0]
        if at_reversal < DENOMINATOR_FLOOR or reversal.xi_MF <= 0.0:
            return None
        major_mf = xi_mf * at_reversal / reversal.xi_MF
        return major_mf, total - major_mf
    at_reversal = branch_fractions(reversal.temperature, constants)[1]
    remaining = total - reversal.xi_MF
    if at_reversal < DENOMINATOR_FLOOR or remaining <= 0.0:
        return None
    major_p = xi_p * at_reversal / remaining
    return total - major_p, major_p
