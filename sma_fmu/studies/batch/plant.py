"""N plants (:class:`~sma_fmu.runtime.plant.PlantStepper`) advanced in lock-step with numpy.

A second implementation of the scalar plant, operation by operation, so the two agree to
rounding (tests/studies/test_batch.py binds them): the zero-order-hold thermal step, the direction
sgn(T+ - T), the major branch through the overflow-free logistic split of
:func:`~sma_fmu.runtime.constant_load.logistic_split`, and in mode "continuous" the minor
branches of :mod:`~sma_fmu.runtime.minor_loops`: a stack of reversal points per run with
wiping out (spec section 6).

Speed: at N = 1,000 a step costs numpy's per-call overhead more than arithmetic, so the
step makes as few calls as it can. Each operation is one numpy call on arrays of N into a
preallocated output, and constants are arrays too (a Python float operand costs a
conversion per call). Paired quantities are the rows of one (2, N) array, so one call
serves both: (xi_MF, xi_P), the heating and cooling masks, the two numerators of the
logistic split. Where the scalar code branches, the batch selects with 0/1 float masks:
a*1 + b*0 = a exactly for finite a and b (masked numpy copies cost several plain calls).
What depends only on the directions (the masks, 1/tau_K of each run's direction, the
sign of each run's direction) is refreshed in the steps in which some direction changes.

The reversal memory: the stacks are the rows of an (N, D) array of T and one of xi_MF
with a count per run (D grows on demand up to the batch's largest ``memory_depth`` + 1).
Reversals and wipes are rare events per run, so they are handled for the runs concerned
only (index arrays; a few runs one pass each with the runtime's own branch_of, many at
once with numpy), in the scalar step's order: push (T_k, xi_MF,k) where the direction changed
(dropping the two oldest points beyond the run's depth), wipe out closed loops, then take
the :class:`~sma_fmu.runtime.minor_loops.Branch` of the new top (value_B, ratio, major_B).
Each run's branch is cached until its stack or its load changes, as the scalar plant
caches it; the per-step check for wiping out is a product and a comparison,
sign(d) T+ >= sign(d) T_B, against a cached bound (+inf below two points). Per step the minor branches then cost
v = value_B + ratio (L_d(T+) - major_B), the clamp into [0, M] and the selection.

The optional model terms (runtime/model_terms.py): dH/k_B of each run's direction (nu_h, nu_c)
is selected with the direction masks; when some run has a second stage, every run's major
branch is the two-stage sum of :mod:`.branches` (exact for one-stage runs: M2 = 0); when
some run has strain terms, every run's length is the expanded, stress-scaled one (exact for
runs without: alpha = 0, the given lengths).
"""
import numpy as np

from sma_fmu.runtime.constant_load import BranchConstants, with_second_stage
from sma_fmu.runtime.constants import COOLING, HEATING, KELVIN_OFFSET
from sma_fmu.runtime.minor_loops import (DENOMINATOR_FLOOR, ReversalPoint, branch_of, push_reversal,
                                         wipe_out)
from sma_fmu.studies.batch.branches import major_fractions, two_stage_fractions, wire_lengths
from sma_fmu.studies.batch.terms import PlantTerms

__all__ = ["BatchPlant", "major_fractions", "FEW_RUNS"]

FEW_RUNS = 8     # events of at most this many runs in a step are handled one run at a time


class BatchPlant(PlantTerms):
    """The plants of a batch; state and outputs are arrays of N (one entry per run).

    Parameters
    ----------
    inputs : BatchInputs
    scenarios : list of Scenario
        Their wire parameters, hysteresis modes and start temperatures.

    :attr:`reversal_count` holds the number of reversal points each run stores and
    :meth:`reversals` a run's stack, oldest first (as ``PlantStepper.reversals``).
    """

    def __init__(self, inputs, scenarios):
        n = inputs.size
        self.inputs = inputs
        p = [s.params for s in scenarios]
        column = lambda name: np.array([getattr(params, name) for params in p])  # noqa: E731
        self.T_room, self.gain = column("T_room"), column("K_th")
        self.R_P, self.R_M, self.R_F = column("R_P"), column("R_M"), column("R_F")
        self._R_PM = np.vstack([self.R_P, self.R_M])      # [R_P; R_M] against [xi_P; xi_M]
        self.l_P, self.l_M, self.l_F = column("l_P"), column("l_M"), column("l_F")
        self.decay = inputs.decay
        self.rest = 1.0 - self.decay                   # 1 - e^(-h/tau_th), as thermal_step has it
        self._decay_rest = np.vstack([self.decay, self.rest])
        self.continuous = np.array([s.hysteresis_mode == "continuous" for s in scenarios])
        self.any_continuous = bool(self.continuous.any())
        self.ones, self.zeros = np.ones(n), np.zeros(n)
        self.halves, self.kelvin = np.full(n, 0.5), np.full(n, KELVIN_OFFSET)
        self.temperature = inputs.T_start.copy()
        self.heating = np.ones(n, dtype=bool)
        # the reversal stacks: rows of (N, capacity) arrays, reversal_count points per run
        self.depth = np.array([params.memory_depth for params in p], dtype=np.int64)
        self._most = int(self.depth[self.continuous].max()) + 1 if self.any_continuous else 1
        self._capacity = min(self._most, 17)
        self._stack_T, self._stack_xi = np.zeros((n, self._capacity)), np.zeros((n, self._capacity))
        self.reversal_count = np.zeros(n, dtype=np.int64)
        self._nested = 0                              # runs with two points or more
        self._bound = np.full(n, np.inf)              # sign(d) T_B (+inf below two points)
        # the branch of each run's top point (runtime Branch), and 0/1, 1/0 "has a stack"
        self._value_B, self._ratio, self._major_B = np.zeros(n), np.zeros(n), np.zeros(n)
        self._has, self._no_stack = np.zeros(n), np.ones(n)
        self._stale = np.zeros(n, dtype=bool)         # load changed: branches to refresh
        self._any_stale = False
        self._w = [np.empty(n) for _ in range(8)]      # work arrays
        self._pairs = [np.empty((2, n)) for _ in range(4)]   # work (2, N) arrays
        self._flags = [np.empty(n, dtype=bool) for _ in range(4)]
        # by direction: [heating; cooling] 0/1 masks, 1/tau_K, sign, minor-branch selectors
        self._masks, self.inverse, self._sign = np.empty((2, n)), np.empty(n), np.empty(n)
        self._on_off, self._off_on = np.zeros((2, n)), np.zeros((2, n))
        self.M, self.xi_F_min, self.minus_energy = np.empty(n), np.empty(n), np.empty(n)
        self._centres = np.empty((2, n))               # [1/tau_K heating; cooling]
        self.inv_heating, self.inv_cooling = self._centres
        self._energies = np.empty((2, n))              # [-dH/k_B heating; cooling]
        self._terms_arrays(p, n)
        self._set(inputs.segment_row(0), np.arange(n))
        np.copyto(self.lengths, self._segment_lengths)
        # state [xi_MF; xi_P; xi_M], and a spare the next step writes into
        self._state, self._spare = np.empty((3, n)), np.empty((3, n))
        np.copyto(self.minus_energy, self._energies[0])
        self._state[0], self._state[1] = self._major(self.temperature, slice(None), True)
        self._next_T = np.empty(n)
        self.xi_F, self.R = np.empty(n), np.empty(n)
        self._directions()
        self._evaluate()

    xi_MF = property(lambda self: self._state[0], doc="Mixed fraction xi_MF [1] per run.")
    xi_P = property(lambda self: self._state[1], doc="Parent fraction xi_P [1] per run.")
    xi_M = property(lambda self: self._state[2], doc="Martensite fraction xi_M [1] per run.")

    def reversals(self, run):
        """The reversal stack of ``run``: [ReversalPoint(T [degC], xi_MF [1])], oldest first."""
        count = int(self.reversal_count[run])
        return [ReversalPoint(T, xi) for T, xi in zip(self._stack_T[run, :count].tolist(),
                                                        self._stack_xi[run, :count].tolist())]

    def _set(self, segments, runs):
        at, rows = self.inputs.constants, segments[runs]
        self.M[runs] = at["M"][rows, runs]
        self.xi_F_min[runs] = at["xi_F_min"][rows, runs]
        self._energies[0, runs] = -at["energy_over_kB"][rows, runs]
        self.inv_heating[runs] = at["inv_centre_heating"][rows, runs]
        self.inv_cooling[runs] = at["inv_centre_cooling"][rows, runs]
        self._set_terms(at, rows, runs)
        self._new_constants = True

    def set_segments(self, segments, previous):
        """Take the branch constants of the runs whose load segment changed (arrays of N)."""
        runs = np.flatnonzero(segments != previous)
        self._set(segments, runs)
        self._stale[runs] = True
        self._any_stale = True

    def _directions(self):
        """The 0/1 masks [heating; cooling], 1/tau_K and sign (+1/-1) of each run's direction."""
        masks = self._masks
        np.copyto(masks[0], self.heating)
        np.subtract(self.ones, masks[0], masks[1])
        np.subtract(masks[0], masks[1], self._sign)
        pair = self._pairs[0]
        np.multiply(self._centres, masks, pair)
        np.add(pair[0], pair[1], self.inverse)     # exactly one term is nonzero
        self._direct_terms(masks, pair)
        self._new_constants = False

    def step(self, power):
        """Advance every plant one step with ``power`` [W] (already >= 0) and its held load."""
        mul, add, sub, div = np.multiply, np.add, np.subtract, np.divide
        w, f = self._w, self._flags
        one = self.ones
        before, after = self.temperature, self._next_T
        # thermal_step: T_room + (T - T_room) decay + K_th u (1 - decay)
        terms = self._pairs[1]
        sub(before, self.T_room, terms[0])
        mul(self.gain, power, terms[1])
        mul(terms, self._decay_rest, terms)            # [(T - T_room) decay; K_th u (1 - decay)]
        add(self.T_room, terms[0], after)
        add(after, terms[1], after)
        # direction: heating if T+ > T, cooling if T+ < T, else unchanged
        up, keep, turned = f[0], f[1], f[2]
        np.greater(after, before, up)
        np.less(after, before, keep)
        np.greater(self.heating, keep, keep)           # heating and not falling
        np.logical_or(up, keep, keep)
        np.not_equal(keep, self.heating, turned)
        changed = np.count_nonzero(turned)
        self.heating, f[1] = keep, self.heating
        if changed or self._new_constants:
            self._directions()
        # major_fractions at T+, into the spare state's rows [xi_MF; xi_P]
        x, e, denominator = w[2], w[3], w[4]
        numerators, state = self._pairs[1], self._spare
        fractions = state[:2]
        add(after, self.kelvin, x)
        div(one, x, x)
        sub(self.inverse, x, x)
        np.sign(x, numerators[1])                      # [-s; s], s = sign(z)
        np.negative(numerators[1], numerators[0])
        np.abs(x, x)
        mul(self.minus_energy, x, x)
        np.exp(x, e)
        add(one, e, denominator)
        # [e if z > 0 else 1; 1 if z > 0 else e] (z = 0: e = 1 either way)
        np.maximum(e, numerators, out=numerators)
        mul(self.M, numerators, fractions)
        div(fractions, denominator, fractions)
        if self.two_stage:                             # the optional second stage
            fractions[0], fractions[1] = two_stage_fractions(after, self._stages(slice(None)))
        if self.any_continuous:
            self._minor_branches(before, after, turned if changed else None, fractions)
        self._spare, self._state = self._state, state
        self._next_T, self.temperature = before, after
        if self.strain:                                # the lengths of the load just held
            np.copyto(self.lengths, self._segment_lengths)
        self._evaluate()

    def _minor_branches(self, before, after, turned, fractions):
        """In mode "continuous": push, wipe out, and replace the major-branch fractions by the
        branch of the top reversal point where a run stores one (PlantStepper.step)."""
        mul, add = np.multiply, np.add
        many = []                                       # runs for the vectorized refresh
        if turned is not None:                          # reversals: direction changes
            reversed_ = np.logical_and(turned, self.continuous, out=turned)
            if np.count_nonzero(reversed_):
                pushed = np.flatnonzero(reversed_)
                if pushed.size <= FEW_RUNS:
                    for run in pushed.tolist():
                        self._settle(run, after, before[run])
                else:
                    self._push(pushed, before)
                    many.append(pushed)
        if self._nested:                                # wiping out: T+ reached or passed T_B
            signed, reached = self._w[5], self._flags[3]
            mul(self._sign, after, signed)
            np.greater_equal(signed, self._bound, reached)
            if np.count_nonzero(reached):
                wiped = np.flatnonzero(reached)
                if wiped.size <= FEW_RUNS and not many:
                    for run in wiped.tolist():
                        self._settle(run, after)
                else:
                    self._wipe(wiped, after)
                    many.append(wiped)
        if self._any_stale:                             # after a load step
            stale = np.flatnonzero(self._stale & (self.reversal_count > 0))
            self._stale[:] = False
            self._any_stale = False
            if stale.size <= FEW_RUNS:
                for run in stale.tolist():
                    self._settle(run, after)
            else:
                many.append(stale)
        if many:
            self._refresh(many[0] if len(many) == 1 else np.unique(np.concatenate(many)))
            mul(self._masks, self._has, self._on_off)
            mul(self._masks[::-1], self._has, self._off_on)
        # fractions_on_branch: v = value_B + ratio (L_d(T) - major_B), clamped into [0, M];
        # heating (xi_MF, xi_P) = (v, M - v), cooling (M - v, v)
        pair, values, minor = self._pairs[0], self._pairs[2], self._pairs[3]
        value, M = values[0], self.M
        mul(fractions, self._masks, pair)
        add(pair[0], pair[1], value)                    # L_d(T+): xi_MF heating, xi_P cooling
        np.subtract(value, self._major_B, value)
        mul(self._ratio, value, value)
        add(self._value_B, value, value)
        np.maximum(value, self.zeros, out=value)
        np.minimum(value, M, out=value)
        np.subtract(M, value, values[1])                # [v; M - v]
        # xi_MF = major (no stack) or v (heating) or M - v (cooling); xi_P likewise.
        # Exactly one term is nonzero, so the sums are exact.
        mul(values, self._on_off, pair)
        add(pair[0], pair[1], minor[0])
        mul(values, self._off_on, pair)
        add(pair[0], pair[1], minor[1])
        mul(fractions, self._no_stack, fractions)
        add(fractions, minor, fractions)

    def _settle(self, run, after, before=None):
        """One run's event with the runtime's own functions: push (T_k = ``before``,
        xi_MF,k) if given, wipe out at T+, then the Branch of the new top (branch_of), the
        wipe-out bound and the selectors."""
        count = self.reversal_count
        heating = bool(self.heating[run])
        points = self.reversals(run)
        if before is not None:
            push_reversal(points, float(before), float(self._state[0, run]), int(self.depth[run]))
        wipe_out(points, after[run], HEATING if heating else COOLING)
        c = len(points)
        if c > self._capacity:
            self._grow(c)
        stack_T, stack_xi = self._stack_T, self._stack_xi
        stack_T[run, :c] = [point.temperature for point in points]
        stack_xi[run, :c] = [point.xi_MF for point in points]
        nested = int(count[run] >= 2)
        count[run] = c
        self._nested += int(c >= 2) - nested
        on, sign = (0, 1.0) if heating else (1, -1.0)
        self._bound[run] = sign * stack_T[run, c - 2] if c >= 2 else np.inf
        self._has[run], self._no_stack[run] = (1.0, 0.0) if c else (0.0, 1.0)
        self._on_off[on, run] = self._off_on[1 - on, run] = 1.0 if c else 0.0
        self._on_off[1 - on, run] = self._off_on[on, run] = 0.0
        if not c:
            return
        constants = BranchConstants(
            float(self.M[run]), None, -float(self.minus_energy[run]),
            float(self.inv_heating[run] if heating else self.inv_cooling[run]), None)
        if self.M2[run] != 0.0:                         # a second stage (w2 > 0)
            constants = with_second_stage(
                constants, 1.0, float(self.M1[run]), float(self.M2[run]),
                -float(self.minus_energy2[run]), float(self.inverse2[run]))
        branch = branch_of(points, c, constants, HEATING if heating else COOLING)
        self._value_B[run], self._ratio[run], self._major_B[run] = branch

    def _grow(self, needed):
        """Widen the stacks to at least ``needed`` slots (doubling, at most depth + 1)."""
        capacity = min(self._most, max(needed, 2 * self._capacity))
        for name in ("_stack_T", "_stack_xi"):
            old = getattr(self, name)
            new = np.zeros((old.shape[0], capacity))
            new[:, :old.shape[1]] = old
            setattr(self, name, new)
        self._capacity = capacity

    def _push(self, runs, before):
        """push_reversal of (T_k, xi_MF,k) for many ``runs``; beyond its depth a run drops
        the two oldest points. Sets the wipe-out bound of ``runs``."""
        count = self.reversal_count
        c = count[runs]
        if int(c.max()) + 1 > self._capacity:
            self._grow(int(c.max()) + 1)
        stack_T, stack_xi = self._stack_T, self._stack_xi
        stack_T[runs, c], stack_xi[runs, c] = before[runs], self._state[0, runs]
        c = c + 1
        over = c > self.depth[runs]
        if over.any():
            full = runs[over]
            stack_T[full, :-2] = stack_T[full, 2:]
            stack_xi[full, :-2] = stack_xi[full, 2:]
            c[over] -= 2
        count[runs] = c
        self._bounds(runs, c)
        self._nested = int(np.count_nonzero(count >= 2))

    def _bounds(self, runs, c):
        """sign(d) T_B of ``runs`` with ``c`` points each (+inf below two)."""
        below = np.maximum(c - 2, 0)
        self._bound[runs] = np.where(c >= 2, self._sign[runs] * self._stack_T[runs, below], np.inf)

    def _wipe(self, runs, after):
        """wipe_out for many ``runs`` (whose T+ reached T_B): pop A and B while T+ reaches T_B."""
        stack_T, count, heating = self._stack_T, self.reversal_count, self.heating
        while runs.size:
            c = count[runs]
            runs, c = runs[c >= 2], c[c >= 2]
            bound, temperature = stack_T[runs, c - 2], after[runs]
            reached = np.where(heating[runs], temperature >= bound, temperature <= bound)
            runs = runs[reached]
            count[runs] -= 2
        self._nested = int(np.count_nonzero(count >= 2))

    def _refresh(self, runs):
        """The cached Branch (value_B, ratio, major_B), stack flags and wipe-out bound of
        many ``runs`` at their present stack, direction and load (branch_of, vectorized)."""
        c = self.reversal_count[runs]
        has = c > 0
        self._has[runs] = has
        self._no_stack[runs] = ~has
        self._bounds(runs, c)
        runs, c = runs[has], c[has]
        if runs.size == 0:
            return
        heating, M = self.heating[runs], self.M[runs]
        nested = c >= 2
        below = np.maximum(c - 2, 0)
        T_A, xi_A = self._stack_T[runs, c - 1], self._stack_xi[runs, c - 1]
        T_B, xi_B = self._stack_T[runs, below], self._stack_xi[runs, below]
        value_A = np.where(heating, xi_A, M - xi_A)
        xi_mf, xi_p = self._major(T_A, runs)
        major_A = np.where(heating, xi_mf, xi_p)
        value_B = np.where(nested, np.where(heating, xi_B, M - xi_B), 0.0)
        xi_mf, xi_p = self._major(T_B, runs)
        major_B = np.where(nested, np.where(heating, xi_mf, xi_p), 0.0)
        denominator = major_A - major_B
        flat = np.abs(denominator) < DENOMINATOR_FLOOR       # the branch stays at A
        self._value_B[runs] = np.where(flat, value_A, value_B)
        self._ratio[runs] = np.where(flat, 0.0, (value_A - value_B) / np.where(
            flat, 1.0, denominator))
        self._major_B[runs] = np.where(flat, 0.0, major_B)

    def _evaluate(self):
        """R = R_P xi_P + R_M xi_M + R_F xi_F, xi_M = xi_MF/2, xi_F = xi_Fmin + xi_M."""
        state, pair, w = self._state, self._pairs[0], self._w[0]
        np.multiply(self.halves, state[0], state[2])
        np.add(self.xi_F_min, state[2], self.xi_F)
        np.multiply(self._R_PM, state[1:], pair)       # [R_P xi_P; R_M xi_M]
        np.add(pair[0], pair[1], self.R)
        np.multiply(self.R_F, self.xi_F, w)
        np.add(self.R, w, self.R)

    def length(self):
        """Wire length x [m] now: l_P xi_P + l_M xi_M + l_F xi_F (with the strain terms:
        :func:`~.branches.wire_lengths`)."""
        if self.strain:
            return wire_lengths(self.temperature, self.xi_P, self.xi_M, self.xi_F, self.l_P,
                                self.lengths[0], self.lengths[1], self._expansion)
        return self.l_P * self.xi_P + self.l_M * self.xi_M + self.l_F * self.xi_F
