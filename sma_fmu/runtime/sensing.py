"""Temperature-sensing model: the inverse of the constant-load model (spec section 5, paper eq. 31).

    xi_MF = (R - R_P - xi_Fmin (R_F - R_P)) / (R_MF - R_P),   valid for 0 < xi_MF < M
    Lambda = ln((M - xi_MF)/xi_MF),   T_K = 1 / (1/tau_K - k_B Lambda / dH(f))

Outside the transformation the resistance is saturated and carries no temperature
information. There xi_MF is clamped into [delta, M - delta], delta = saturation_margin * M,
the clamped temperature is returned and ``saturated`` is set. The flag is set whenever
the clamp acts: outside (0, M) and also within delta of either end.

On a minor branch of section 6 (after a reversal) the inverse maps the point to the major
branch at the same temperature (:func:`~.minor_loops.major_equivalent`) and inverts that;
the clamp then acts twice: into the band the load allows, then into what the branch reaches.
"""
import math
from collections import namedtuple

from .checks import direction_sign, require_positive
from .constant_load import branch_constants
from .constants import KELVIN_OFFSET
from .minor_loops import major_equivalent
from .reachable_band import band_of_branch

__all__ = ["SensedTemperature", "mixed_fractions_of_resistance", "temperature_of_fractions",
           "temperature_on_branch", "sense_temperature"]

SensedTemperature = namedtuple("SensedTemperature", ["temperature", "saturated"])
SensedTemperature.__doc__ = "Sensed temperature [degC] and whether the resistance was saturated."
_new_tuple = tuple.__new__  # builds the namedtuple in C (see plant.py)


def mixed_fractions_of_resistance(resistance, constants, params):
    """(xi_MF, xi_P) [1] that give ``resistance`` [ohm] on a branch with ``constants``.

    Both are computed as differences from the saturated ends, so each is accurate
    near its own end of the transformation.
    """
    span = params.R_MF - params.R_P
    r_hot, r_cold = band_of_branch(constants, params)
    return (resistance - r_hot) / span, (r_cold - resistance) / span


def _clamped(xi_mf, total, delta):
    """(xi_MF, xi_P, True) moved to the nearer end of [delta, total - delta] (one is outside)."""
    if not xi_mf >= delta:  # also NaN
        return delta, total - delta, True
    return total - delta, delta, True


def temperature_of_fractions(xi_mf, xi_p, constants, margin):
    """Invert a major branch: (xi_MF, xi_P) [1] -> :class:`SensedTemperature`.

    ``margin`` is the relative clamp delta/M [1].
    """
    delta = margin * constants.M
    saturated = False
    if not (xi_mf >= delta and xi_p >= delta):
        xi_mf, xi_p, saturated = _clamped(xi_mf, constants.M, delta)
    exponent = math.log(xi_p / xi_mf)
    inverse_kelvin = constants.inv_centre_K - exponent / constants.energy_over_kB
    if not inverse_kelvin > 0.0:
        raise ValueError(
            f"temperature-sensing inverse diverges at Lambda = {exponent!r}: dH(f)/k_B = "
            f"{constants.energy_over_kB!r} K is too small for the hysteresis centre")
    return _new_tuple(SensedTemperature, (1.0 / inverse_kelvin - KELVIN_OFFSET, saturated))


def temperature_on_branch(xi_mf, xi_p, constants, direction, reversal, margin):
    """Invert the branch the wire is on: (xi_MF, xi_P) [1] -> :class:`SensedTemperature`.

    ``reversal`` None: the major branch of ``direction`` (as :func:`temperature_of_fractions`).
    A :class:`~.minor_loops.Reversal`: the minor branch that left it in ``direction``. The
    fractions are first clamped into [delta, M - delta] (what the load allows), then the
    major equivalent is clamped the same way (what this branch reaches); ``saturated`` is
    set when either clamp acts. Where the branch is flat (its denominator below the floor,
    so no temperature moves it) the result is the reversal temperature, saturated.
    No argument checks: this is on the compensator's hot path.
    """
    if reversal is None:
        return temperature_of_fractions(xi_mf, xi_p, constants, margin)
    delta = margin * constants.M
    clamped = False
    if not (xi_mf >= delta and xi_p >= delta):
        xi_mf, xi_p, clamped = _clamped(xi_mf, constants.M, delta)
    major = major_equivalent(xi_mf, xi_p, constants, direction, reversal)
    if major is None:
        return _new_tuple(SensedTemperature, (reversal.temperature, True))
    sensed = temperature_of_fractions(major[0], major[1], constants, margin)
    if clamped and not sensed.saturated:
        return _new_tuple(SensedTemperature, (sensed.temperature, True))
    return sensed


def sense_temperature(resistance, load, direction, params, reversal=None):
    """Temperature [degC] of a wire with ``resistance`` [ohm] under ``load`` [kg].

    ``direction`` is +1/"heating" or -1/"cooling". With ``reversal`` (a
    :class:`~.minor_loops.Reversal`) the point is on the continuous-mode minor branch
    that left that reversal; otherwise on the major branch (see :func:`temperature_on_branch`).
    """
    resistance = require_positive("resistance", resistance)
    sign = direction_sign(direction)
    constants = branch_constants(load, sign, params)
    xi_mf, xi_p = mixed_fractions_of_resistance(resistance, constants, params)
    return temperature_on_branch(xi_mf, xi_p, constants, sign, reversal,
                                 params.saturation_margin)
