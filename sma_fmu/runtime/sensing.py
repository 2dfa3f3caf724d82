"""Temperature-sensing model: the inverse of the constant-load model (spec section 5, paper eq. 31).

    xi_MF = (R - R_P - xi_Fmin (R_F - R_P)) / (R_MF - R_P),   valid for 0 < xi_MF < M
    Lambda = ln((M - xi_MF)/xi_MF),   T_K = 1 / (1/tau_K - k_B Lambda / dH(f))

With a second stage (w2 > 0, :mod:`.constant_load`) no closed form exists: 1/T_K is found
by a safeguarded Newton iteration on Lambda(1/T_K), bracketed by the two single-stage closed
forms (:func:`~.two_stage_root.two_stage_inverse`); the compensator starts it from its last
temperature on the same branch (``near``), its first step along the tangent it kept there
(``line``, :func:`temperature_with_tangent`).

Outside the transformation the resistance is saturated and carries no temperature
information. There xi_MF is clamped into [delta, M - delta], delta = saturation_margin * M,
the clamped temperature is returned and ``saturated`` is set. The flag is set whenever
the clamp acts: outside (0, M) and also within delta of either end.

On the minor branches of section 6 (a stack of reversal points) the inverse walks the
stack: a target beyond the branch's end point B lies on the outer branch (A and B are
popped, as a loop that closes is wiped out), and on the branch A -> B the affine map of
section 6 is inverted in closed form, L_d(T) = L_d(T_B) + (v* - v_B)(L_d(T_A) - L_d(T_B))/
(v_A - v_B) (v = xi_MF heating, M - xi_MF cooling), then T from the major branch's inverse.
The clamp then acts twice: into the band the load allows, then into what the major branch
reaches.
"""
import math
from collections import namedtuple

from .checks import direction_sign, require_positive
from .constant_load import branch_constants
from .constants import KELVIN_OFFSET
from .constants import HEATING
from .minor_loops import (DENOMINATOR_FLOOR, fractions_of_value, fractions_on_stack, major_value,
                          value_of)
from .reachable_band import band_of_branch
from .two_stage_root import ROOT_CAP, ROOT_TOLERANCE_K, two_stage_inverse

__all__ = ["SensedTemperature", "mixed_fractions_of_resistance", "temperature_of_fractions",
           "temperature_with_tangent", "temperature_on_stack", "invert_on_stack",
           "sense_temperature", "inverse_method"]

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


def temperature_of_fractions(xi_mf, xi_p, constants, margin, near=None):
    """Invert a major branch: (xi_MF, xi_P) [1] -> :class:`SensedTemperature`.

    ``margin`` is the relative clamp delta/M [1]. ``near`` [degC], if given, is a temperature
    close to the answer (a compensator's last one): a two-stage search starts there when it
    lies inside the search's bracket. The answer is the same to the search's tolerance
    (1e-12 K), not bit for bit.
    """
    return temperature_with_tangent(xi_mf, xi_p, constants, margin, near)[0]


def temperature_with_tangent(xi_mf, xi_p, constants, margin, near=None, line=None):
    """:func:`temperature_of_fractions` that also returns Lambda's tangent at the answer:
    (SensedTemperature, line), line = (Lambda [1], -dLambda/d(1/T_K) [K]) of a two-stage
    search (None for one stage, or where the slope underflowed).

    A compensator keeps the line with its temperature and passes both back at the next
    step on the same branch (``near``, ``line``): the search's first step is then the
    tangent's, without an evaluation (:func:`~.two_stage_root.two_stage_inverse`).
    """
    delta = margin * constants.M
    saturated = False
    if not (xi_mf >= delta and xi_p >= delta):
        xi_mf, xi_p, saturated = _clamped(xi_mf, constants.M, delta)
    exponent = math.log(xi_p / xi_mf)
    inverse_kelvin = constants.inv_centre_K - exponent / constants.energy_over_kB
    tangent = None
    if constants.w2 != 0.0:
        start = None   # 1/(near + 273.15), where that is a temperature above absolute zero
        if near is not None:
            start = near + KELVIN_OFFSET
            start = 1.0 / start if start > 0.0 else None
        inverse_kelvin, slope = two_stage_inverse(xi_mf, xi_p, exponent, inverse_kelvin,
                                                  constants, start, line)
        if slope > 0.0:
            tangent = (exponent, slope)
    elif not inverse_kelvin > 0.0:
        raise ValueError(
            f"temperature-sensing inverse diverges at Lambda = {exponent!r}: dH(f)/k_B = "
            f"{constants.energy_over_kB!r} K is too small for the hysteresis centre")
    sensed = _new_tuple(SensedTemperature, (1.0 / inverse_kelvin - KELVIN_OFFSET, saturated))
    return sensed, tangent


def temperature_on_stack(xi_mf, xi_p, constants, direction, points, margin, count=None):
    """Invert the branch the wire is on: (xi_MF, xi_P) [1] -> (:class:`SensedTemperature`, kept).

    ``points[:count]`` (default all) is the stack of :class:`~.minor_loops.ReversalPoint`
    (empty: the major branch of ``direction``, as :func:`temperature_of_fractions`). The
    fractions are first clamped into [delta, M - delta] (what the load allows); a target
    at or beyond B pops A and B (the loop it closes is wiped out, as the plant wipes when T
    reaches or passes T_B) and the walk repeats; on the
    branch A -> B the major value is found in closed form and inverted, clamped again into
    what the major branch reaches. ``saturated`` is set when either clamp acts. Where the
    branch is flat (a denominator below the floor) the result is T_A, saturated. ``kept``
    is how many points of the stack remain. No argument checks: the compensator's hot path.
    """
    count = len(points) if count is None else count
    if not count:
        return temperature_of_fractions(xi_mf, xi_p, constants, margin), 0
    total = constants.M
    delta = margin * total
    clamped = False
    if not (xi_mf >= delta and xi_p >= delta):
        xi_mf, xi_p, clamped = _clamped(xi_mf, total, delta)
    heating = direction == HEATING
    target = xi_mf if heating else xi_p
    while count:
        top = points[count - 1]
        value_A = value_of(top, total, heating)
        if count >= 2:
            below = points[count - 2]
            value_B = value_of(below, total, heating)
            offset = target - value_B
            if offset * (value_A - value_B) < 0.0 or offset == 0.0:   # at or beyond B: outer
                count -= 2
                continue
            major_B = major_value(below.temperature, constants, heating)
        else:
            value_B = major_B = 0.0
        major_A = major_value(top.temperature, constants, heating)
        span = value_A - value_B
        if abs(major_A - major_B) < DENOMINATOR_FLOOR or abs(span) < DENOMINATOR_FLOOR:
            return _new_tuple(SensedTemperature, (top.temperature, True)), count
        major = major_B + (target - value_B) * ((major_A - major_B) / span)
        major_mf, major_p = fractions_of_value(major, total, heating)
        sensed = temperature_of_fractions(major_mf, major_p, constants, margin)
        if clamped and not sensed.saturated:
            sensed = _new_tuple(SensedTemperature, (sensed.temperature, True))
        return sensed, count
    sensed = temperature_of_fractions(xi_mf, xi_p, constants, margin)   # the stack emptied
    if clamped and not sensed.saturated:
        sensed = _new_tuple(SensedTemperature, (sensed.temperature, True))
    return sensed, 0


def invert_on_stack(xi_mf, xi_p, constants, direction, points, margin):
    """The minor-loop compensator's inversion of one sample: (SensedTemperature, the stack
    after the walk, xi_MF it assumes) [degC], [points], [1].

    :func:`temperature_on_stack`, the stack cut to the points it kept (a copy only when it
    shrank), and the fraction the state is assumed at: the target's, or where the clamp
    acted, the branch's at the clamped temperature.
    """
    sensed, kept = temperature_on_stack(xi_mf, xi_p, constants, direction, points, margin)
    if kept < len(points):
        points = points[:kept]
    if sensed.saturated:
        xi_mf = fractions_on_stack(sensed.temperature, constants, direction, points)[0]
    return sensed, points, xi_mf


def sense_temperature(resistance, load, direction, params, reversals=()):
    """Temperature [degC] of a wire with ``resistance`` [ohm] under ``load`` [kg].

    ``direction`` is +1/"heating" or -1/"cooling". With ``reversals`` (a stack of
    :class:`~.minor_loops.ReversalPoint`, oldest first) the point is on the continuous-mode
    branch of that memory; otherwise on the major branch (see :func:`temperature_on_stack`).
    """
    resistance = require_positive("resistance", resistance)
    sign = direction_sign(direction)
    constants = branch_constants(load, sign, params)
    xi_mf, xi_p = mixed_fractions_of_resistance(resistance, constants, params)
    return temperature_on_stack(xi_mf, xi_p, constants, sign, list(reversals),
                                params.saturation_margin)[0]


def inverse_method(two_stage):
    """How :func:`temperature_of_fractions` finds T [text]: what the FMUs' pages say, so the
    words follow the code. ``two_stage``: the branch has a second stage (w2 > 0)."""
    if not two_stage:
        return "closed form, T_K = 1/(1/tau_K - k_B Lambda/dH(f))"
    return (f"Newton's method on 1/T_K, safeguarded: started from the compensator's last "
            f"temperature on the same branch, its first step along the tangent kept there, "
            f"else from the steeper stage's "
            f"closed-form inverse, kept inside the bracket of the two stages' closed forms "
            f"(a step that would leave it halves it instead), stopped when the error left in "
            f"T is below {ROOT_TOLERANCE_K:g} K (about 2 evaluations from the last temperature, "
            f"3 without it; at most {ROOT_CAP} rounds)")
