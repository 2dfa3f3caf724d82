"""The minor-loop inverse of N compensators at once (``FeedforwardStepper(inverse="minor-loop")``).

Each compensator keeps its own reversal memory, taken from the reference direction d_ref:
when d_ref changes at sample k, the reversal point is what it assumed at sample k - 1,
(T_ref,k-1, xi_MF,k-1) (the fraction of R_ref(t_k-1), or where that sample was clamped,
the fraction of its branch at the clamped T_ref,k-1). Before the first reversal it inverts
the major branch (the batch's major inverse, computed for every column first). After a
reversal the target fraction is mapped to the major branch at the same temperature
(:func:`~sma_fmu.runtime.minor_loops.major_equivalent`), clamped into what that branch
reaches, and inverted; where the branch is flat T_ref is the reversal temperature and
``saturated`` is set. The branch constants are those of the present load (and direction),
so a load step re-evaluates the branch and the reversal point stays.

The compensator is open loop, so a chunk of steps is computed at once between the samples
at which some compensator reverses: per such stretch the reversal memory and each
column's direction are fixed (so, without a load step in the chunk, the branch's value at
the reversal point is one row), and at its end the memory of the reversing columns is
updated from the stretch's last row (the carry holds it across chunks). Results go
straight into the caller's arrays (``out=``). The operations are those of
:mod:`~sma_fmu.runtime.sensing` and :mod:`~sma_fmu.runtime.minor_loops`, in their order;
tests/test_batch.py binds the two.
"""
import numpy as np

from sma_fmu.runtime.constants import KELVIN_OFFSET
from sma_fmu.runtime.minor_loops import DENOMINATOR_FLOOR
from sma_fmu.studies.batch_plant import major_fractions

__all__ = ["clamp_fractions", "temperature_of_fractions", "MinorLoopMemory"]

_CONSTANTS = ("delta", "upper", "M", "energy")   # per load segment: one row without a load step


def clamp_fractions(xi_mf, xi_p, delta, upper):
    """Move fractions outside [delta, M - delta] to the nearer edge, in place; returns the flag.

    As :func:`~sma_fmu.runtime.sensing.temperature_of_fractions` clamps (NaN counts as low);
    ``delta``, ``upper`` = M - delta [1] broadcast against the (c, k) fractions.
    """
    low = np.greater_equal(xi_mf, delta)
    np.logical_not(low, out=low)
    high = np.greater_equal(xi_p, delta)
    np.logical_or(high, low, out=high)
    np.logical_not(high, out=high)                  # not low and not xi_p >= delta
    if low.any():                                   # usually none: R_ref inside the band
        np.copyto(xi_mf, delta, where=low)
        np.copyto(xi_p, upper, where=low)
    if high.any():
        np.copyto(xi_mf, upper, where=high)
        np.copyto(xi_p, delta, where=high)
    return np.logical_or(low, high, out=low)


def temperature_of_fractions(xi_mf, xi_p, inverse, energy, T, exponent, bad):
    """Invert clamped major-branch fractions into ``T`` [degC], ``exponent`` (Lambda) and
    ``bad`` (1/T_K <= 0: diverged), given ``inverse`` = 1/tau_K [1/K] and ``energy`` =
    dH/k_B [K]: T = 1/(1/tau_K - Lambda/E) - 273.15, Lambda = ln(xi_P/xi_MF)."""
    np.divide(xi_p, xi_mf, out=exponent)
    np.log(exponent, out=exponent)
    np.divide(exponent, energy, out=T)
    np.subtract(inverse, T, out=T)                  # 1/T_K
    np.greater(T, 0.0, out=bad)
    np.logical_not(bad, out=bad)
    np.divide(1.0, T, out=T)
    np.subtract(T, KELVIN_OFFSET, out=T)


def _at_reversal(T_r, M, energy, inverse, heating):
    """L_h(T_r) heating, M - L_c(T_r) (its xi_P) cooling, at the present branch constants."""
    xi_mf, xi_p = major_fractions(T_r, M, -energy, inverse)
    return np.where(heating, xi_mf, xi_p)


class MinorLoopMemory:
    """Reversal memory and inversion of ``count`` minor-loop compensators (inverse columns)."""

    def __init__(self, count):
        self.T_r, self.xi_r = np.zeros(count), np.zeros(count)   # [degC], [1]
        self.has = np.zeros(count, dtype=bool)                   # a reversal is stored
        self.last_T, self.last_xi = np.zeros(count), np.zeros(count)   # T_ref,k-1, xi_MF,k-1
        self.last_heating = None                                 # d_ref,k-1 (True: heating)

    def invert(self, stage, out):
        """The inverse of a chunk of steps, into ``out``.

        ``stage``: (c, k) views: ``mf``, ``p`` (fractions of R_ref after the first clamp),
        ``inverse`` (1/tau_K of d_ref), ``heating`` (d_ref), and the :data:`_CONSTANTS`
        (one row when no load step is inside the chunk); ``out``: (c, k) views ``T_ref``,
        ``saturated`` (holding the first clamp's flag), ``bad``, ``exponent``.
        """
        heating = stage["heating"]
        rows = heating.shape[0]
        uniform = stage["M"].shape[0] == 1
        before = heating[0] if self.last_heating is None else self.last_heating  # k = 0: none
        reversing = np.empty(heating.shape, dtype=bool)
        np.not_equal(heating[0], before, reversing[0])
        np.not_equal(heating[1:], heating[:-1], reversing[1:])
        first = 0
        for last in np.flatnonzero(reversing.any(axis=1)).tolist() + [rows]:
            if last > first:
                self._stretch(slice(first, last), stage, out, uniform)
                self._remember(last - 1, stage, out, uniform)
            if last < rows:
                turn = reversing[last]
                self.T_r[turn], self.xi_r[turn] = self.last_T[turn], self.last_xi[turn]
                self.has[turn] = True
            first = last
        self.last_heating = heating[-1].copy()

    def _stretch(self, rows, stage, out, uniform):
        """Rows ``rows`` (no reversal inside): the minor branch's inverse where one is stored."""
        constant = (lambda name: stage[name]) if uniform else (  # noqa: E731
            lambda name: stage[name][rows])
        heating = stage["heating"][rows.start]          # d_ref is fixed in the stretch
        M, energy = constant("M"), constant("energy")
        inverse = stage["inverse"][rows]
        T_r, xi_r, has = self.T_r, self.xi_r, self.has
        at_reversal = _at_reversal(T_r, M, energy, inverse[:1] if uniform else inverse, heating)
        remaining = M - xi_r
        flat = (at_reversal < DENOMINATOR_FLOOR) | np.where(heating, xi_r <= 0.0,
                                                             remaining <= 0.0)
        flat &= has
        # major_equivalent: heating xi_MF = xi_mf L_h(T_r)/xi_r,
        # cooling xi_P = xi_p xi_P,c(T_r)/(M - xi_r)
        mf, p = stage["mf"][rows], stage["p"][rows]
        major_mf = mf * at_reversal
        major_mf /= xi_r
        major_p = p * at_reversal
        major_p /= remaining
        new_mf = np.where(heating, major_mf, M - major_p)
        new_p = np.where(heating, M - major_mf, major_p)
        if not has.all():                               # before the first reversal: major
            new_mf, new_p = np.where(has, new_mf, mf), np.where(has, new_p, p)
        clamped = clamp_fractions(new_mf, new_p, constant("delta"), constant("upper"))
        T_ref, bad, saturated = out["T_ref"][rows], out["bad"][rows], out["saturated"][rows]
        temperature_of_fractions(new_mf, new_p, inverse, energy, T_ref, out["exponent"][rows],
                                 bad)
        np.copyto(T_ref, T_r, where=flat)               # flat: the reversal temperature
        np.greater(bad, flat, out=bad)                  # bad and not flat
        np.logical_or(saturated, clamped, out=saturated)
        np.logical_or(saturated, flat, out=saturated)

    def _remember(self, row, stage, out, uniform):
        """(T_ref, xi_MF) assumed at ``row``: the fraction of R_ref, or if clamped the branch's."""
        self.last_T = out["T_ref"][row].copy()
        self.last_xi = stage["mf"][row].copy()          # = the fraction of R_ref where not clamped
        chosen = np.flatnonzero(out["saturated"][row])
        if chosen.size == 0:
            return
        at = 0 if uniform else row
        heating, inverse = stage["heating"][row, chosen], stage["inverse"][row, chosen]
        M, energy = stage["M"][at, chosen], stage["energy"][at, chosen]
        T = self.last_T[chosen]
        branch_mf, branch_p = major_fractions(T, M, -energy, inverse)   # branch_fractions
        has, T_r, xi_r = self.has[chosen], self.T_r[chosen], self.xi_r[chosen]
        # minor_branch_fractions: heating xi_MF = clamp(xi_r L_h(T)/L_h(T_r)) (flat: xi_r),
        # cooling xi_P = clamp((M - xi_r) xi_P,c(T)/xi_P,c(T_r)) (flat: M - xi_r)
        at_reversal = _at_reversal(T_r, M, energy, inverse, heating)
        flat = at_reversal < DENOMINATOR_FLOOR
        base = np.where(heating, xi_r, M - xi_r)
        value = np.where(flat, base, base * np.where(heating, branch_mf, branch_p) / at_reversal)
        value = np.where(value < 0.0, 0.0, np.where(value > M, M, value))
        minor = np.where(heating, value, M - value)
        self.last_xi[chosen] = np.where(has, minor, branch_mf)
