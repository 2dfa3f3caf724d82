"""The inverse of a two-stage major branch (spec section 5 with the optional second stage):
1/T_K where the branch has a target (xi_MF, xi_P), by a safeguarded Newton iteration.

    Lambda(u) = ln(xi_P(u)/xi_MF(u)),   u = 1/T_K,   xi = stage 1's halves + stage 2's

is smooth and decreasing in u (linear for one stage: the closed form). Each stage's closed
form, the u where that stage alone would hold the target, brackets the root: the branch is
a weighted mean of two curves that both rise with u. The search keeps that bracket, narrows
it by each residual's sign, and halves it where a Newton step would leave it. A caller
that knows a nearby root (the compensator: its last one) may start there. Every
fraction is computed from its own end (a logistic split), so Lambda keeps its digits near
saturation. The C family (c_family/runtime/sensing.c) runs the same operations in the same
order, so the two agree bit for bit.
"""
import math

from .constant_load import two_stage_fractions

__all__ = ["ROOT_CAP", "ROOT_TOLERANCE_K", "two_stage_inverse"]

ROOT_CAP = 200   # rounds of the search (Newton steps or halvings); 1-6 in practice
ROOT_TOLERANCE_K = 1e-14   # K: bound on the error a last Newton step leaves in T (1e-12 promised)
_log, _exp = math.log, math.exp


def two_stage_inverse(xi_mf, xi_p, exponent, inverse_kelvin, constants, start=None, line=None):
    """(1/T_K [1/K] where a two-stage major branch has (xi_MF, xi_P) [1], -Lambda' [K] there).

    ``exponent`` = ln(xi_P/xi_MF) and ``inverse_kelvin`` is stage 1's closed-form inverse;
    stage 2's is the other end of the bracket. Where a closed form is <= 0 (that stage alone
    never falls to the target), the low end is 1/T_K = 0: the root exists if the branch is
    below the target there, infinitely hot; else the inverse diverges (ValueError, as the
    one-stage inverse).

    The start: ``start`` [1/K] where it is given and inside the bracket (a compensator's
    last root, 1/(T_ref,k-1 + 273.15): its reference moves little between steps, and the
    search then skips the start below, a fifth of its time). With ``line`` = (Lambda_0 [1],
    -Lambda'_0 [K]), Lambda's tangent at ``start`` (the last root's target and the slope this
    returned with it), the first u is that tangent's Newton step to ``exponent``,
    start + (Lambda_0 - exponent)/(-Lambda'_0), where it lies inside the bracket: a round
    without an evaluation (about 2 evaluations instead of 3 from the last root). Else: at the steep stage's
    closed form u_s (the stage of larger dH/k_B = E), the broad stage holds (mf_b, p_b); the
    steep stage's closed-form inverse of what is left, u', damped by the broad stage's slope
    there: u_s + (u' - u_s)/(1 + (E_b q_b/E_s)(1/left_P + 1/left_MF)), one Newton step on
    u - u'(u). If the broad stage alone holds more than the target (nothing left on one
    side), the steep stage is taken as saturated (all P or all MF) and the broad stage's
    inverse of the rest is the start. Outside the bracket: its midpoint.

    Each round evaluates both stages (logistic_split's operations, inlined, and the first
    half's derivative q_k = M_k e^z/(1 + e^z)^2), the residual r = Lambda(u) - exponent and
    -Lambda'(u) = (E1 q1 + E2 q2)(1/xi_MF + 1/xi_P); r narrows the bracket, then u - r/Lambda'
    is the next u unless it leaves the bracket (or there is no slope: a fraction
    underflowed), when the bracket is halved. It returns when r = 0, when the bracket is two
    neighbouring doubles, or after a Newton step dx with dx^2 <= (:data:`ROOT_TOLERANCE_K` /
    E_max) u^2: since |Lambda''| <= 2 E_max |Lambda'|, the step leaves an error of about
    E_max dx^2 in u, that many kelvin in T. At most :data:`ROOT_CAP` rounds. The slope
    returned is -Lambda' of the last evaluation (0.0 where a fraction underflowed there).
    """
    total1, energy1, centre1, total2, energy2, centre2 = constants.stages
    exp, log = _exp, _log   # locals: this runs at every compensator step
    other = centre2 - exponent / energy2
    if inverse_kelvin <= other:
        low, high = inverse_kelvin, other
    else:
        low, high = other, inverse_kelvin
    if not low > 0.0:
        low = 0.0
        mf, p = two_stage_fractions(0.0, constants)
        if not (high > 0.0 and ((mf < xi_mf) if xi_mf <= xi_p else (p > xi_p))):
            raise ValueError(
                f"temperature-sensing inverse diverges at Lambda = {exponent!r}: the two-stage "
                f"branch does not reach the target at any temperature (dH(f)/k_B = "
                f"{energy1!r} K, second stage {energy2!r} K)")
    if start is not None and low < start < high:   # a caller's start
        u = start
        if line is not None:   # the tangent's step from it, where that stays in the bracket
            tangent = start + (line[0] - exponent) / line[1]
            if low < tangent < high:
                u = tangent
        steepest = energy1 if energy1 >= energy2 else energy2
    else:   # the search's own start (written out: a call costs ~0.2 us in Python)
        if energy1 >= energy2:
            steepest, centre_s, total_s, energy_b, centre_b, total_b, u = (
                energy1, centre1, total1, energy2, centre2, total2, inverse_kelvin)
        else:
            steepest, centre_s, total_s, energy_b, centre_b, total_b, u = (
                energy2, centre2, total2, energy1, centre1, total1, other)
        z = energy_b * (centre_b - u)   # the broad stage at u_s, split as logistic_split does
        if z > 0.0:
            e = exp(-z)
            d = 1.0 + e
            half = total_b * e / d      # the smaller half, MF
            left_mf, left_p = xi_mf - half, xi_p - total_b / d
        else:
            e = exp(z)
            d = 1.0 + e
            half = total_b * e / d      # the smaller half, P
            left_mf, left_p = xi_mf - total_b / d, xi_p - half
        if left_mf > 0.0 and left_p > 0.0:
            target = centre_s - log(left_p / left_mf) / steepest
            u = u + (target - u) / (1.0 + energy_b * (half / d) / steepest * (
                1.0 / left_p + 1.0 / left_mf))
        elif left_mf > 0.0:   # the broad stage alone holds more P: the steep one is all MF
            u = centre_b - log(xi_p / (xi_mf - total_s)) / energy_b if xi_mf > total_s else low
        else:                 # it holds more MF: the steep one is all P
            u = centre_b - log((xi_p - total_s) / xi_mf) / energy_b if xi_p > total_s else low
        if not low < u < high:
            u = 0.5 * (low + high)
    limit = ROOT_TOLERANCE_K / steepest
    for _ in range(ROOT_CAP):
        # stage 1, then stage 2, split as logistic_split does; written out twice because a
        # function call per stage costs ~15 % of an inversion in Python
        z = energy1 * (centre1 - u)
        if z > 0.0:
            e = exp(-z)
            d = 1.0 + e
            mf1, p1 = total1 * e / d, total1 / d
            q1 = mf1 / d
        else:
            e = exp(z)
            d = 1.0 + e
            mf1, p1 = total1 / d, total1 * e / d
            q1 = p1 / d
        z = energy2 * (centre2 - u)
        if z > 0.0:
            e = exp(-z)
            d = 1.0 + e
            mf2, p2 = total2 * e / d, total2 / d
            q2 = mf2 / d
        else:
            e = exp(z)
            d = 1.0 + e
            mf2, p2 = total2 / d, total2 * e / d
            q2 = p2 / d
        mf, p = mf1 + mf2, p1 + p2
        if mf > 0.0 and p > 0.0:
            residual = log(p / mf) - exponent
            slope = (energy1 * q1 + energy2 * q2) * (1.0 / mf + 1.0 / p)   # -Lambda'
        else:   # a fraction underflowed (extreme values): its sign only, then halve
            residual, slope = p - mf, 0.0
        if residual > 0.0:   # Lambda above the target: the root is colder
            low = u
        elif residual < 0.0:
            high = u
        else:
            return u, slope
        if slope > 0.0:
            step = residual / slope
            new = u + step
            if low <= new <= high:   # new == u: the step is below u's last bit
                if step * step <= limit * new * new:
                    return new, slope
                if new != u:
                    u = new
                    continue
        new = 0.5 * (low + high)
        if not low < new < high:   # the bracket is two neighbouring doubles
            return u, slope
        u = new
    return u, slope

