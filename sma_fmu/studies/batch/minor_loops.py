"""The minor-loop inverse of N compensators at once (``FeedforwardStepper(inverse="minor-loop")``).

Each compensator keeps its own stack of reversal points, driven by the reference direction
d_ref with the plant's rules (spec section 6): when d_ref changes at sample k it pushes what
it assumed at sample k - 1, (T_ref,k-1, xi_MF,k-1) (the fraction of R_ref(t_k-1), or where
that sample was saturated, the fraction of its branch at T_ref,k-1), dropping the two oldest
points beyond ``memory_depth``. Each sample inverts the branch of the stack, walking it
(:func:`~sma_fmu.runtime.sensing.temperature_on_stack`): a target beyond the branch's end B
pops A and B for good (the loop it closes is wiped out); on the branch A -> B the major
value is found in closed form and inverted; a flat branch gives T_A, saturated.

The compensator is open loop, so a chunk of samples is computed at once. Between two
*events* of a compensator (a change of d_ref, or a target beyond B of its top pair) its
stack and direction are fixed, so every sample is the closed-form inverse of one branch:
a few numpy calls over (samples, compensators). An event sample is computed with the
runtime's own functions on that compensator's stack (a list of ReversalPoint, the
reference state), so every stored point, and so every decision to pop, is the scalar
path's bit for bit; it then continues from the sample after. The chunk is walked in
rounds: the first over all its samples and compensators, each later one over a window of
:data:`WINDOW` samples from the earliest unfinished one, for the compensators whose next
sample lies in it; a round finishes, per compensator, the samples before its first event
and the event itself. Events are rare (d_ref reverses a few times a period), so most
chunks take one round. The operations are those of :mod:`~sma_fmu.runtime.sensing` and
:mod:`~sma_fmu.runtime.minor_loops`, in their order; tests/studies/test_batch.py binds the two.
"""
import math

import numpy as np

from sma_fmu.runtime.constant_load import BranchConstants, with_second_stage
from sma_fmu.runtime.constants import COOLING, HEATING, KELVIN_OFFSET
from sma_fmu.runtime.minor_loops import DENOMINATOR_FLOOR, push_reversal
from sma_fmu.runtime.sensing import invert_on_stack
from sma_fmu.studies.batch.branches import (major_fractions, two_stage_fractions,
                                            two_stage_temperatures)

__all__ = ["clamp_fractions", "temperature_of_fractions", "MinorLoopMemory", "WINDOW"]

WINDOW = 64      # samples per round after the first (which takes the whole chunk)
# what an event needs of a sample (the last sample of a chunk is carried to the next)
_CARRIED = ("raw_mf", "raw_p", "M", "energy", "inverse", "heating", "M1", "M2",
            "energy2_heating", "energy2_cooling", "inv2_heating", "inv2_cooling")


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
        np.copyto(xi_mf, np.broadcast_to(delta, xi_mf.shape), where=low)
        np.copyto(xi_p, np.broadcast_to(upper, xi_p.shape), where=low)
    if high.any():
        np.copyto(xi_mf, np.broadcast_to(upper, xi_mf.shape), where=high)
        np.copyto(xi_p, np.broadcast_to(delta, xi_p.shape), where=high)
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


class MinorLoopMemory:
    """Reversal stacks and inversion of ``len(margins)`` minor-loop compensators (columns).

    ``margins``: each column's saturation margin delta/M [1]; ``depths``: its memory_depth.
    :attr:`points` holds each column's stack (a list of ReversalPoint, oldest first), as
    ``FeedforwardStepper.reversals``.
    """

    def __init__(self, margins, depths, two_stage=None):
        count = len(margins)
        # which columns have the optional second stage (their branches: branches.py)
        self.two_stage = np.zeros(count, dtype=bool) if two_stage is None else np.array(
            two_stage, dtype=bool)
        self.any_two_stage = bool(self.two_stage.any())
        self.margins, self.depths = [float(m) for m in margins], [int(d) for d in depths]
        self.points = [[] for _ in range(count)]
        # the top pair of each stack: A = the top, B = the point below (if any)
        self.count = np.zeros(count, dtype=np.int64)
        self.T_A, self.xi_A = np.zeros(count), np.zeros(count)
        self.T_B, self.xi_B = np.zeros(count), np.zeros(count)
        self.last_heating = None       # d_ref of the last sample done (None: none yet)
        self._carry = None             # that sample's inputs, {name: (columns,)}
        self._offset = 0               # sample index of the chunk's first row
        # the sample of each column's last event and what it assumed there (T_ref, xi_MF)
        self._event_sample = [-2] * count
        self._event_assumed = [(math.nan, math.nan)] * count

    def invert(self, stage, out):
        """The inverse of a chunk of samples, into ``out``.

        ``stage``: (c, k) arrays (one row where the value is the same for every sample):
        ``raw_mf``, ``raw_p`` (the fractions of R_ref), ``mf``, ``p`` and ``clamped``
        (after the first clamp into [delta, M - delta], and its flag), ``heating``
        (d_ref), ``inverse`` (1/tau_K of d_ref), ``inv_heating``, ``inv_cooling``, ``M``,
        ``energy`` (dH/k_B), ``delta``, ``upper``; ``out``: (c, k) arrays ``T_ref``,
        ``saturated``, ``bad`` (the inverse diverges), ``exponent`` (Lambda).
        """
        heating = stage["heating"]
        rows, columns = heating.shape
        reversing = np.empty((rows, columns), dtype=bool)
        if self.last_heating is None:                   # the first sample: no reversal
            reversing[0] = False
        else:
            np.not_equal(heating[0], self.last_heating, reversing[0])
        np.not_equal(heating[1:], heating[:-1], reversing[1:])
        cursor = np.zeros(columns, dtype=np.int64)      # each column's first sample not done
        self._round(0, rows, None, cursor, stage, out, reversing)
        while True:
            waiting = np.flatnonzero(cursor < rows)
            if waiting.size == 0:
                break
            low = int(cursor[waiting].min())
            high = min(low + WINDOW, rows)
            self._round(low, high, waiting[cursor[waiting] < high], cursor, stage, out,
                        reversing)
        last = rows - 1
        self._carry = {name: np.array(np.broadcast_to(stage[name][-1], (columns,)))
                       for name in _CARRIED if name in stage}
        self.last_heating = np.array(heating[last])
        self._offset += rows

    def _round(self, low, high, chosen, cursor, stage, out, reversing):
        """Samples ``low`` ... ``high - 1`` of the columns ``chosen`` (None: all): done up to
        each column's first event, and the event itself; advances ``cursor``."""
        every = chosen is None
        columns = slice(None) if every else chosen

        def pick(name):
            values = stage[name]
            values = values[low:high] if values.shape[0] > 1 else values
            return values[:, columns]

        # each column's direction at its cursor: its direction until its next event
        heating = stage["heating"][0] if every else stage["heating"][cursor[chosen], chosen]
        T, saturated, bad, exponent, pops = self._branches(pick, heating, columns)
        events = np.logical_or(reversing[low:high, columns], pops)
        if not every:       # samples before a column's cursor are done already
            done = np.arange(low, high)[:, None] < cursor[chosen]
            events &= ~done
            keep = ~done
            for name, values in (("T_ref", T), ("saturated", saturated), ("bad", bad),
                                 ("exponent", exponent)):
                target = out[name][low:high, chosen]
                np.copyto(target, values, where=keep)
                out[name][low:high, chosen] = target
        else:
            out["T_ref"][low:high], out["saturated"][low:high] = T, saturated
            out["bad"][low:high], out["exponent"][low:high] = bad, exponent
        found = events.any(axis=0)
        first = np.argmax(events, axis=0) + low
        indices = np.arange(cursor.size) if every else chosen
        cursor[indices] = high
        for column, row in zip(indices[found].tolist(), first[found].tolist()):
            self._event(column, row, stage, out, bool(reversing[row, column]))
            cursor[column] = row + 1

    def _branches(self, pick, heating, columns):
        """(T_ref, saturated, bad, Lambda, pops) of the picked samples with each column's
        present stack and direction ``heating`` (its direction until its next event).

        temperature_on_stack without the walk: ``pops`` marks where the target lies beyond
        B of the top pair (an event, computed again there).
        """
        count = self.count[columns]
        has, nested = count > 0, count >= 2
        mf, p, clamped = pick("mf"), pick("p"), pick("clamped")
        M, energy, delta, upper = pick("M"), pick("energy"), pick("delta"), pick("upper")
        inverse = np.where(heating, pick("inv_heating"), pick("inv_cooling"))
        own = np.where(heating, pick("energy_heating"), pick("energy_cooling"))   # dH/k_B of d
        stages = self._stages(pick, heating, own, inverse) if self.any_two_stage else None
        T_A, xi_A = self.T_A[columns], self.xi_A[columns]
        T_B, xi_B = self.T_B[columns], self.xi_B[columns]
        target = np.where(heating, mf, p)
        value_A = np.where(heating, xi_A, M - xi_A)
        value_B = np.where(nested, np.where(heating, xi_B, M - xi_B), 0.0)
        xi_mf, xi_p = self._major(T_A, M, own, inverse, stages)
        major_A = np.where(heating, xi_mf, xi_p)
        xi_mf, xi_p = self._major(T_B, M, own, inverse, stages)
        major_B = np.where(nested, np.where(heating, xi_mf, xi_p), 0.0)
        spread, span = major_A - major_B, value_A - value_B
        offset = target - value_B
        pops = np.logical_and(nested, (offset * span < 0.0) | (offset == 0.0))
        flat = has & ((np.abs(spread) < DENOMINATOR_FLOOR) | (np.abs(span) < DENOMINATOR_FLOOR))
        major = major_B + offset * (spread / span)
        rest = M - major
        new_mf = np.where(has, np.where(heating, major, rest), mf)
        new_p = np.where(has, np.where(heating, rest, major), p)
        second = clamp_fractions(new_mf, new_p, delta, upper)
        shape = new_mf.shape
        T, exponent, bad = np.empty(shape), np.empty(shape), np.empty(shape, dtype=bool)
        temperature_of_fractions(new_mf, new_p, pick("inverse"), energy, T, exponent, bad)
        if stages is not None:
            sample = self._stages(pick, None, energy, pick("inverse"))   # d_ref of the sample
            two_stage_temperatures(new_mf, new_p, exponent, pick("inverse"), energy, sample,
                                   self.two_stage[columns], T, bad)
        if flat.any():                                  # flat: T_A, saturated
            np.copyto(T, np.broadcast_to(T_A, shape), where=flat)
            bad &= ~flat
        saturated = clamped | second | flat
        return T, saturated, bad, exponent, pops

    def _stages(self, pick, heating, energy, inverse):
        """The two-stage constants of the picked samples, in the direction ``heating`` (each
        column's) or, with None, in each sample's d_ref (``pick("heating")``)."""
        if heating is None:
            heating = pick("heating")
        return {"M1": pick("M1"), "M2": pick("M2"), "minus_energy": -energy,
                "minus_energy2": -np.where(heating, pick("energy2_heating"),
                                           pick("energy2_cooling")),
                "inverse": inverse,
                "inverse2": np.where(heating, pick("inv2_heating"), pick("inv2_cooling"))}

    @staticmethod
    def _major(temperature, M, energy, inverse, stages):
        """(xi_MF, xi_P) of the major branches at ``temperature`` [degC] (one or two stages)."""
        if stages is None:
            return major_fractions(temperature, M, -energy, inverse)
        return two_stage_fractions(temperature, stages)

    def _event(self, column, row, stage, out, reversal):
        """Sample ``row`` of ``column`` with the runtime's functions (FeedforwardStepper._invert):
        push on a reversal, walk the stack, invert; the stack and the memory follow."""
        def at(name, where):
            values = stage[name]
            return float(values[where if values.shape[0] > 1 else 0, column])

        points = self.points[column]
        sample = self._offset + row
        if reversal:
            if self._event_sample[column] == sample - 1:      # the previous sample was an event
                assumed = self._event_assumed[column]
            elif row > 0:
                assumed = self._assumed(column, points, {name: at(name, row - 1)
                                                         for name in _CARRIED if name in stage})
            else:                                             # the previous chunk's last sample
                assumed = self._assumed(column, points, {
                    name: float(values[column]) for name, values in self._carry.items()})
            points = list(points)
            push_reversal(points, assumed[0], assumed[1], self.depths[column])
        xi_mf, xi_p = at("raw_mf", row), at("raw_p", row)
        constants = self._constants(column, {name: at(name, row) for name in _CARRIED
                                             if name in stage})
        direction = HEATING if at("heating", row) else COOLING
        try:
            sensed, points, fraction = invert_on_stack(xi_mf, xi_p, constants, direction, points,
                                                       self.margins[column])
            T, saturated, bad = sensed.temperature, sensed.saturated, False
        except ValueError:                              # diverged: the run goes to the library
            T, saturated, bad, fraction = math.nan, True, True, math.nan
        self._keep(column, points)
        self._event_sample[column] = sample
        self._event_assumed[column] = (T, fraction)
        out["T_ref"][row, column], out["saturated"][row, column] = T, saturated
        out["bad"][row, column], out["exponent"][row, column] = bad, math.nan

    def _constants(self, column, sample):
        """The BranchConstants of one sample (``sample``: {name: float} of _CARRIED)."""
        constants = BranchConstants(sample["M"], None, sample["energy"], sample["inverse"], None)
        if not self.two_stage[column]:
            return constants
        heating = sample["heating"]
        return with_second_stage(
            constants, 1.0, sample["M1"], sample["M2"],
            sample["energy2_heating" if heating else "energy2_cooling"],
            sample["inv2_heating" if heating else "inv2_cooling"])

    def _assumed(self, column, points, sample):
        """(T_ref, xi_MF) the compensator assumed at a sample that was no event (its stack
        ``points`` unchanged by it): FeedforwardStepper._invert's state."""
        xi_mf, xi_p = sample["raw_mf"], sample["raw_p"]
        constants = self._constants(column, sample)
        direction = HEATING if sample["heating"] else COOLING
        try:
            sensed, _, xi_mf = invert_on_stack(xi_mf, xi_p, constants, direction, points,
                                               self.margins[column])
        except ValueError:
            return math.nan, math.nan
        return sensed.temperature, xi_mf

    def _keep(self, column, points):
        """Make ``points`` the stack of ``column`` and cache its top pair."""
        self.points[column] = points
        count = len(points)
        self.count[column] = count
        if count:
            self.T_A[column], self.xi_A[column] = points[-1]
        if count >= 2:
            self.T_B[column], self.xi_B[column] = points[-2]
