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
at which some compensator reverses: per such stretch the reversal memory is fixed, and at
its end the memory of the reversing columns is updated from the stretch's last row (the
carry holds it across chunks). The operations are those of
:mod:`~sma_fmu.runtime.sensing` and :mod:`~sma_fmu.runtime.minor_loops`, in their order;
tests/test_batch.py binds the two.
"""
import numpy as np

from sma_fmu.runtime.constants import KELVIN_OFFSET
from sma_fmu.runtime.minor_loops import DENOMINATOR_FLOOR
from sma_fmu.studies.batch_plant import major_fractions

__all__ = ["clamp_fractions", "temperature_of_fractions", "MinorLoopMemory"]


def clamp_fractions(xi_mf, xi_p, delta, upper):
    """(xi_MF, xi_P, clamped): fractions outside [delta, M - delta] moved to the nearer edge.

    As :func:`~sma_fmu.runtime.sensing.temperature_of_fractions` clamps (NaN counts as low);
    ``delta``, ``upper`` = M - delta [1].
    """
    low = ~(xi_mf >= delta)
    high = ~low & ~(xi_p >= delta)
    return (np.where(low, delta, np.where(high, upper, xi_mf)),
            np.where(low, upper, np.where(high, delta, xi_p)), low | high)


def temperature_of_fractions(xi_mf, xi_p, inverse, energy):
    """(T [degC], Lambda, 1/T_K) of clamped major-branch fractions; 1/T_K <= 0: diverged.

    ``inverse`` = 1/tau_K of the direction [1/K], ``energy`` = dH/k_B [K].
    """
    exponent = np.log(xi_p / xi_mf)
    inverse_kelvin = inverse - exponent / energy
    return 1.0 / inverse_kelvin - KELVIN_OFFSET, exponent, inverse_kelvin


def _at_reversal(T_r, M, energy, inverse, heating):
    """L_h(T_r) heating, M - L_c(T_r) (its xi_P) cooling, at the present branch constants."""
    xi_mf, xi_p = major_fractions(T_r, M, -energy, inverse)
    return np.where(heating, xi_mf, xi_p)


class MinorLoopMemory:
    """Reversal memory and inversion of the minor-loop compensators (columns ``columns``).

    ``columns``: index array of the batch's inverse columns that use the minor-loop inverse.
    """

    def __init__(self, columns):
        count = columns.size
        self.columns = columns
        self.T_r, self.xi_r = np.zeros(count), np.zeros(count)   # [degC], [1]
        self.has = np.zeros(count, dtype=bool)                   # a reversal is stored
        self.last_T, self.last_xi = np.zeros(count), np.zeros(count)   # T_ref,k-1, xi_MF,k-1
        self.last_heating = None                                 # d_ref,k-1 (True: heating)

    def invert(self, stage, out):
        """Overwrite the major inverse in ``out`` where a minor-loop column holds a reversal.

        ``stage``: the chunk's (rows, C) arrays (broadcastable) of every inverse column:
        ``xi_mf`` (of R_ref, unclamped), ``mf``, ``p``, ``clamped`` (after the first clamp),
        ``delta``, ``upper``, ``M``, ``energy``, ``inverse``, ``heating``; ``out``: the
        (rows, C) arrays ``T_ref``, ``saturated``, ``bad``, ``exponent`` of the major inverse.
        """
        heating = stage["heating"]
        rows = heating.shape[0]
        part = {name: np.broadcast_to(value, (rows, value.shape[1]))[:, self.columns]
                if value.shape[1] > 1 else np.broadcast_to(value, (rows, self.columns.size))
                for name, value in stage.items()}
        result = {name: out[name][:, self.columns] for name in out}
        heating = part["heating"]
        before = heating[0] if self.last_heating is None else self.last_heating  # k = 0: none
        reversing = np.empty((rows, self.columns.size), dtype=bool)
        np.not_equal(heating[0], before, reversing[0])
        np.not_equal(heating[1:], heating[:-1], reversing[1:])
        first = 0
        for last in [int(r) for r in np.flatnonzero(reversing.any(axis=1))] + [rows]:
            if last > first:
                self._stretch(first, last, part, result)
                self._remember(last - 1, part, result)
            if last < rows:
                turn = reversing[last]
                self.T_r[turn], self.xi_r[turn] = self.last_T[turn], self.last_xi[turn]
                self.has[turn] = True
            first = last
        self.last_heating = heating[-1].copy()
        for name, values in result.items():
            out[name][:, self.columns] = values

    def _stretch(self, first, last, part, result):
        """Rows first ... last - 1 of the columns with a reversal: the minor branch's inverse."""
        cols = np.flatnonzero(self.has)
        if cols.size == 0:
            return
        take = lambda name: part[name][first:last, cols]  # noqa: E731
        heating, M, energy, inverse = take("heating"), take("M"), take("energy"), take("inverse")
        T_r, xi_r = self.T_r[cols], self.xi_r[cols]
        at_reversal = _at_reversal(T_r, M, energy, inverse, heating)
        remaining = M - xi_r
        flat = (at_reversal < DENOMINATOR_FLOOR) | np.where(heating, xi_r <= 0.0,
                                                             remaining <= 0.0)
        # major_equivalent: heating xi_MF = xi_mf L_h(T_r)/xi_r; cooling xi_P = xi_p ... /(M - xi_r)
        major_mf = take("mf") * at_reversal / xi_r
        major_p = take("p") * at_reversal / remaining
        mf = np.where(heating, major_mf, M - major_p)
        p = np.where(heating, M - major_mf, major_p)
        mf, p, clamped = clamp_fractions(mf, p, take("delta"), take("upper"))
        T_ref, exponent, inverse_kelvin = temperature_of_fractions(mf, p, inverse, energy)
        rows = slice(first, last)
        result["T_ref"][rows, cols] = np.where(flat, T_r, T_ref)
        result["saturated"][rows, cols] = take("clamped") | clamped | flat
        result["bad"][rows, cols] = ~flat & ~(inverse_kelvin > 0.0)
        result["exponent"][rows, cols] = exponent

    def _remember(self, row, part, result):
        """(T_ref, xi_MF) assumed at ``row``: the fraction of R_ref, or of the branch if clamped."""
        self.last_T = result["T_ref"][row].copy()
        self.last_xi = part["xi_mf"][row].copy()
        chosen = np.flatnonzero(result["saturated"][row])
        if chosen.size == 0:
            return
        take = lambda name: part[name][row, chosen]  # noqa: E731
        heating, M, energy, inverse = take("heating"), take("M"), take("energy"), take("inverse")
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
