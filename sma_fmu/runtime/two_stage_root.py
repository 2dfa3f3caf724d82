"""The inverse of a two-stage major branch (spec section 5 with issue 36's second stage):
1/T_K where the branch has a target (xi_MF, xi_P), by a safeguarded Newton iteration.

    Lambda(u) = ln(xi_P(u)/xi_MF(u)),   u = 1/T_K,   xi = stage 1's halves + stage 2's

is smooth and decreasing in u (linear for one stage: the closed form). Each stage's closed
form, the u where that stage alone would hold the target, brackets the root: the branch is
a weighted mean of two curves that both rise with u. The search keeps that bracket, narrows
it by each residual's sign, and halves it where a Newton step would leave it. Every
fraction is computed from its own end (a logistic split), so Lambda keeps its digits near
saturation. The C family (c_family/runtime/sensing.c) runs the same operations in the same
order, so the two agree bit for bit.
"""
import math

from .constant_load import logistic_split, two_stage_fractions

__all__ = ["ROOT_CAP", "ROOT_TOLERANCE_K", "two_stage_inverse", "newton_start"]

ROOT_CAP = 200   # rounds of the search (Newton steps or halvings); 1-6 in practice
ROOT_TOLERANCE_K = 1e-14   # K: bound on the error a last Newton step leaves in T (1e-12 promised)
_log, _exp = math.log, math.exp


def newton_start(xi_mf, xi_p, steep, broad, inverse_steep, low, high):
    """The first u [1/K]: the steeper stage's closed-form inverse of what the broader stage
    leaves at the steeper stage's own closed form ``inverse_steep``.

    ``steep`` and ``broad`` are (E, 1/tau_K, M_k) [K, 1/K, 1] of the stage with the larger
    and the smaller dH/k_B. If the broad stage alone holds more than the target there
    (a half <= 0 left), the steep stage is taken as saturated, all P or all MF, and the broad
    stage's inverse of the rest is used. Outside (low, high), or with nothing left, the
    bracket's midpoint. Exact where the broad stage is flat or the steep one saturated.
    """
    energy, inverse_centre, total = steep
    energy_b, inverse_centre_b, total_b = broad
    mf_b, p_b = logistic_split(total_b, energy_b * (inverse_centre_b - inverse_steep))
    left_mf, left_p = xi_mf - mf_b, xi_p - p_b
    u = math.nan
    if left_mf > 0.0 and left_p > 0.0:
        u = inverse_centre - _log(left_p / left_mf) / energy
    elif left_mf > 0.0:   # the broad stage alone holds more P: the steep one is all MF
        if xi_mf > total:
            u = inverse_centre_b - _log(xi_p / (xi_mf - total)) / energy_b
    elif xi_p > total:    # the broad stage alone holds more MF: the steep one is all P
        u = inverse_centre_b - _log((xi_p - total) / xi_mf) / energy_b
    if not low < u < high:   # also NaN
        u = 0.5 * (low + high)
    return u


def two_stage_inverse(xi_mf, xi_p, exponent, inverse_kelvin, constants):
    """1/T_K [1/K] where a two-stage major branch has (xi_MF, xi_P) [1].

    ``exponent`` = ln(xi_P/xi_MF) and ``inverse_kelvin`` is stage 1's closed-form inverse;
    stage 2's is the other end of the bracket. Where a closed form is <= 0 (that stage alone
    never falls to the target), the low end is 1/T_K = 0: the root exists if the branch is
    below the target there, infinitely hot; else the inverse diverges (ValueError, as the
    one-stage inverse). From :func:`newton_start`, each round evaluates both stages
    (a logistic split each, inlined: the halves and the first half's derivative), the
    residual r = Lambda(u) - exponent and Lambda'(u) = -(E1 q1 + E2 q2)(1/xi_P + 1/xi_MF)
    (q_k = M_k e^z/(1 + e^z)^2); r narrows the bracket, then u - r/Lambda' is the next u
    unless it leaves the bracket (or there is no slope: a fraction underflowed), when the
    bracket is halved. It returns when r = 0, when the bracket is two neighbouring doubles,
    or after a Newton step dx with E_max dx^2 <= :data:`ROOT_TOLERANCE_K` u^2: since
    |Lambda''| <= 2 E_max |Lambda'|, the step leaves an error of about E_max dx^2 in u,
    that many kelvin in T. At most :data:`ROOT_CAP` rounds.
    """
    energy1, energy2 = constants.energy_over_kB, constants.energy2_over_kB
    centre1, centre2 = constants.inv_centre_K, constants.inv_centre2_K
    total1, total2 = constants.M1, constants.M2
    other = centre2 - exponent / energy2
    low, high = (inverse_kelvin, other) if inverse_kelvin <= other else (other, inverse_kelvin)
    if not low > 0.0:
        low = 0.0
        mf, p = two_stage_fractions(0.0, constants)
        if not (high > 0.0 and ((mf < xi_mf) if xi_mf <= xi_p else (p > xi_p))):
            raise ValueError(
                f"temperature-sensing inverse diverges at Lambda = {exponent!r}: the two-stage "
                f"branch does not reach the target at any temperature (dH(f)/k_B = "
                f"{energy1!r} K, second stage {energy2!r} K)")
    if energy1 >= energy2:
        steepest = energy1
        u = newton_start(xi_mf, xi_p, (energy1, centre1, total1), (energy2, centre2, total2),
                         inverse_kelvin, low, high)
    else:
        steepest = energy2
        u = newton_start(xi_mf, xi_p, (energy2, centre2, total2), (energy1, centre1, total1),
                         other, low, high)
    for _ in range(ROOT_CAP):
        z = energy1 * (centre1 - u)   # stage 1 split as logistic_split does
        if z > 0.0:
            e = _exp(-z)
            d = 1.0 + e
            mf1, p1 = total1 * e / d, total1 / d
            q1 = mf1 / d
        else:
            e = _exp(z)
            d = 1.0 + e
            mf1, p1 = total1 / d, total1 * e / d
            q1 = p1 / d
        z = energy2 * (centre2 - u)   # and stage 2
        if z > 0.0:
            e = _exp(-z)
            d = 1.0 + e
            mf2, p2 = total2 * e / d, total2 / d
            q2 = mf2 / d
        else:
            e = _exp(z)
            d = 1.0 + e
            mf2, p2 = total2 / d, total2 * e / d
            q2 = p2 / d
        mf, p = mf1 + mf2, p1 + p2
        if mf > 0.0 and p > 0.0:
            residual = _log(p / mf) - exponent
            slope = (energy1 * q1 + energy2 * q2) * (1.0 / mf + 1.0 / p)   # -Lambda'
        else:   # a fraction underflowed (extreme values): its sign only, then halve
            residual, slope = p - mf, 0.0
        if residual > 0.0:   # Lambda above the target: the root is colder
            low = u
        elif residual < 0.0:
            high = u
        else:
            return u
        if slope > 0.0:
            step = residual / slope
            new = u + step
            if low <= new <= high:   # new == u: the step is below u's last bit
                if steepest * step * step <= ROOT_TOLERANCE_K * new * new:
                    return new
                if new != u:
                    u = new
                    continue
        new = 0.5 * (low + high)
        if not low < new < high:   # the bracket is two neighbouring doubles
            return u
        u = new
    return u
