"""Major branches, their two-stage inverse and the wire length for arrays of runs (numpy).

The scalar runtime's formulas (:mod:`sma_fmu.runtime.constant_load`, :mod:`~.sensing`,
:mod:`~.model_terms`), operation by operation, so the batch agrees with it to rounding
(numpy's exp and log may differ from the math module's in the last bit). A one-stage run is
a two-stage one with M1 = M, M2 = 0 and a zero second energy: its second half is exactly 0,
so the sum is the one-stage split bit for bit, and the batch needs no per-run branching.
"""
import numpy as np

from sma_fmu.runtime.constants import KELVIN_OFFSET
from sma_fmu.runtime.two_stage_root import ROOT_CAP, ROOT_TOLERANCE_K

__all__ = ["major_fractions", "split_at_inverse", "split_with_slope", "two_stage_at_inverse",
           "two_stage_temperatures", "two_stage_fractions", "two_stage_inverse", "wire_lengths"]


def major_fractions(temperature, M, minus_energy, inv_centre):
    """(xi_MF, xi_P) [1] on major branches, as :func:`branch_fractions` computes them.

    ``temperature`` [degC]; ``M`` [1]; ``minus_energy`` = -dH/k_B [K]; ``inv_centre`` =
    1/tau_K [1/K]. With z = E (1/tau_K - 1/T_K) and e = exp(-|z|) (no overflow; -|z| =
    (-E) |1/tau_K - 1/T_K| exactly, as E > 0): xi_MF = M e/(1 + e) and xi_P = M/(1 + e)
    for z > 0, swapped otherwise. The swap takes max(e, [z <= 0]) and max(e, [z > 0]) as
    numerators, exact because 0 < e <= 1. (:meth:`BatchPlant.step` inlines the same calls.)
    """
    return split_at_inverse(1.0 / (temperature + KELVIN_OFFSET), M, minus_energy, inv_centre)


def split_at_inverse(inverse_kelvin, M, minus_energy, inv_centre):
    """:func:`major_fractions` at 1/T_K = ``inverse_kelvin`` [1/K] (logistic_split's halves)."""
    x = inv_centre - inverse_kelvin
    positive = (x > 0.0).astype(float)
    e = np.exp(minus_energy * np.abs(x))
    denominator = 1.0 + e
    return (M * np.maximum(e, 1.0 - positive) / denominator,
            M * np.maximum(e, positive) / denominator)


def two_stage_at_inverse(inverse_kelvin, c):
    """(xi_MF, xi_P) of two-stage branches at 1/T_K (``c``: a dict of arrays M1, M2,
    minus_energy, minus_energy2, inverse, inverse2): stage 1's halves plus stage 2's."""
    mf1, p1 = split_at_inverse(inverse_kelvin, c["M1"], c["minus_energy"], c["inverse"])
    mf2, p2 = split_at_inverse(inverse_kelvin, c["M2"], c["minus_energy2"], c["inverse2"])
    return mf1 + mf2, p1 + p2


def two_stage_fractions(temperature, c):
    """:func:`two_stage_at_inverse` at ``temperature`` [degC]."""
    return two_stage_at_inverse(1.0 / (temperature + KELVIN_OFFSET), c)


def split_with_slope(inverse_kelvin, M, minus_energy, inv_centre):
    """:func:`split_at_inverse` (the same operations) and the first half's derivative by
    -z, M e/(1 + e)^2 [1]: the smaller half over 1 + e, as the runtime's inlined split."""
    x = inv_centre - inverse_kelvin
    positive = (x > 0.0).astype(float)
    e = np.exp(minus_energy * np.abs(x))
    denominator = 1.0 + e
    mf = M * np.maximum(e, 1.0 - positive) / denominator
    p = M * np.maximum(e, positive) / denominator
    return mf, p, np.minimum(mf, p) / denominator


def _newton_start(xi_mf, xi_p, u1, u2, c, low, high):
    """(start u [1/K], the steep stage's dH/k_B [K]) per element, as the runtime's
    :func:`~sma_fmu.runtime.two_stage_root.two_stage_inverse` starts: the steep stage is the
    one of larger dH/k_B (stage 1 on a tie), ``u1`` and ``u2`` the two closed forms [1/K]."""
    first = -c["minus_energy"] >= -c["minus_energy2"]
    pick = lambda one, two: np.where(first, one, two)  # noqa: E731
    energy, total = pick(-c["minus_energy"], -c["minus_energy2"]), pick(c["M1"], c["M2"])
    centre = pick(c["inverse"], c["inverse2"])
    energy_b = pick(-c["minus_energy2"], -c["minus_energy"])
    centre_b = pick(c["inverse2"], c["inverse"])
    u = pick(u1, u2)
    mf_b, p_b, slope_b = split_with_slope(u, pick(c["M2"], c["M1"]), -energy_b, centre_b)
    left_mf, left_p = xi_mf - mf_b, xi_p - p_b
    both = (left_mf > 0.0) & (left_p > 0.0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        target = centre - np.log(left_p / left_mf) / energy
        damped = u + (target - u) / (1.0 + energy_b * slope_b / energy * (1.0 / left_p
                                                                          + 1.0 / left_mf))
        all_mf = np.where(xi_mf > total,
                          centre_b - np.log(xi_p / (xi_mf - total)) / energy_b, low)
        all_p = np.where(xi_p > total, centre_b - np.log((xi_p - total) / xi_mf) / energy_b, low)
    u = np.where(both, damped, np.where(left_mf > 0.0, all_mf, all_p))
    return np.where((low < u) & (u < high), u, 0.5 * (low + high)), energy


def two_stage_inverse(xi_mf, xi_p, exponent, inverse_kelvin, c):
    """1/T_K [1/K] of two-stage branches and ``bad`` (the branch does not reach the target
    at any temperature), as :func:`sma_fmu.runtime.two_stage_root.two_stage_inverse`: the
    same start, Newton steps, halvings and stops per element, each element leaving the
    rounds where the runtime returns (at most ROOT_CAP rounds)."""
    other = c["inverse2"] - exponent / -c["minus_energy2"]
    low, high = np.minimum(inverse_kelvin, other), np.maximum(inverse_kelvin, other)
    open_end = ~(low > 0.0)              # a stage alone never falls to the target: from 0
    bad = np.zeros(low.shape, dtype=bool)
    if open_end.any():
        low = np.where(open_end, 0.0, low)
        mf, p = two_stage_at_inverse(np.zeros(low.shape), c)
        reaches = (high > 0.0) & np.where(xi_mf <= xi_p, mf < xi_mf, p > xi_p)
        bad = open_end & ~reaches
    u, steepest = _newton_start(xi_mf, xi_p, inverse_kelvin, other, c, low, high)
    limit = ROOT_TOLERANCE_K / steepest
    energy1, energy2 = -c["minus_energy"], -c["minus_energy2"]
    result, active = u.copy(), ~bad
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for _ in range(ROOT_CAP):
            if not active.any():
                break
            mf1, p1, q1 = split_with_slope(u, c["M1"], c["minus_energy"], c["inverse"])
            mf2, p2, q2 = split_with_slope(u, c["M2"], c["minus_energy2"], c["inverse2"])
            mf, p = mf1 + mf2, p1 + p2
            ok = (mf > 0.0) & (p > 0.0)
            residual = np.where(ok, np.log(p / mf) - exponent, p - mf)
            slope = np.where(ok, (energy1 * q1 + energy2 * q2) * (1.0 / mf + 1.0 / p), 0.0)
            low = np.where(active & (residual > 0.0), u, low)
            high = np.where(active & (residual < 0.0), u, high)
            zero = active & ~(residual > 0.0) & ~(residual < 0.0)
            step = residual / slope
            new = u + step
            newton = active & ~zero & (slope > 0.0) & (low <= new) & (new <= high)
            stop = newton & (step * step <= limit * new * new)
            moves = newton & ~stop & (new != u)
            middle = 0.5 * (low + high)
            halve = active & ~zero & ~stop & ~moves
            collapsed = halve & ~((low < middle) & (middle < high))
            result = np.where(zero | collapsed, u, np.where(stop, new, result))
            active = active & ~(zero | stop | collapsed)
            u = np.where(moves, new, np.where(halve, middle, u))
    return np.where(active, u, result), bad


def wire_lengths(temperature, xi_p, xi_m, xi_f, l_P, length_M, length_F, terms):
    """x [m] with thermal expansion (:func:`sma_fmu.runtime.model_terms.wire_length`);
    ``terms``: arrays alpha_P, alpha_MF, T_alpha (0, 0, any for runs without: exact)."""
    offset = temperature - terms["T_alpha"]
    grow = 1.0 + terms["alpha_MF"] * offset
    return (l_P * (1.0 + terms["alpha_P"] * offset) * xi_p
            + length_M * grow * xi_m + length_F * grow * xi_f)


def two_stage_temperatures(xi_mf, xi_p, exponent, inverse, energy, stages, mask, T, bad):
    """In place, for the columns ``mask`` (bool, one per column) of two-stage inverses: T
    [degC] and ``bad`` from :func:`two_stage_inverse`. The other
    arguments are (c, k) or broadcast to it: the clamped fractions, Lambda, 1/tau_K, dH/k_B,
    and ``stages`` {M1, M2, minus_energy, minus_energy2, inverse, inverse2}."""
    columns = np.flatnonzero(mask)
    if columns.size == 0:
        return
    shape = T.shape

    def sub(values):
        return np.broadcast_to(values, shape)[:, columns]

    first = sub(inverse) - sub(exponent) / sub(energy)      # stage 1's closed form, 1/T_K
    middle, diverged = two_stage_inverse(sub(xi_mf), sub(xi_p), sub(exponent), first,
                                         {name: sub(values) for name, values in stages.items()})
    with np.errstate(divide="ignore"):              # a diverged element: 1/0, flagged bad
        T[:, columns] = 1.0 / middle - KELVIN_OFFSET
    bad[:, columns] = diverged                      # in place of stage 1's closed-form test
