"""N plants (:class:`~sma_fmu.runtime.plant.PlantStepper`) advanced in lock-step with numpy.

A second implementation of the scalar plant, operation by operation, so the two agree to
rounding (tests/test_batch.py binds them): the zero-order-hold thermal step, the direction
sgn(T+ - T), the major branch through the overflow-free logistic split of
:func:`~sma_fmu.runtime.constant_load.logistic_split`, and in mode "continuous" the minor
branches of :mod:`~sma_fmu.runtime.minor_loops`.

Speed: at N = 1,000 a step costs numpy's per-call overhead more than arithmetic, so the
step makes as few calls as it can. Each operation is one numpy call on arrays of N into a
preallocated output, and constants are arrays too (a Python float operand costs a
conversion per call). Paired quantities are the rows of one (2, N) array, so one call
serves both: (xi_MF, xi_P), the heating and cooling masks, the two numerators of the
logistic split. Where the scalar code branches, the batch selects with 0/1 float masks:
a*1 + b*0 = a exactly for finite a and b (masked numpy copies cost several plain calls).
What depends only on the directions (the masks, 1/tau_K of each run's direction, the
minor-branch selectors) is refreshed in the steps in which some direction changes; what
depends on the reversal point and the load (the minor branch's terms at the reversal) at a
reversal or a load step.
"""
import numpy as np

from sma_fmu.runtime.constant_load import BranchConstants, branch_fractions
from sma_fmu.runtime.constants import KELVIN_OFFSET
from sma_fmu.runtime.minor_loops import DENOMINATOR_FLOOR

__all__ = ["BatchPlant", "major_fractions"]


def major_fractions(temperature, M, minus_energy, inv_centre):
    """(xi_MF, xi_P) [1] on major branches, as :func:`branch_fractions` computes them.

    ``temperature`` [degC]; ``M`` [1]; ``minus_energy`` = -dH/k_B [K]; ``inv_centre`` =
    1/tau_K [1/K]. With z = E (1/tau_K - 1/T_K) and e = exp(-|z|) (no overflow; -|z| =
    (-E) |1/tau_K - 1/T_K| exactly, as E > 0): xi_MF = M e/(1 + e) and xi_P = M/(1 + e)
    for z > 0, swapped otherwise. The swap takes max(e, [z <= 0]) and max(e, [z > 0]) as
    numerators, exact because 0 < e <= 1. (:meth:`BatchPlant.step` inlines the same calls.)
    """
    x = inv_centre - 1.0 / (temperature + KELVIN_OFFSET)
    positive = (x > 0.0).astype(float)
    e = np.exp(minus_energy * np.abs(x))
    denominator = 1.0 + e
    return (M * np.maximum(e, 1.0 - positive) / denominator,
            M * np.maximum(e, positive) / denominator)


class BatchPlant:
    """The plants of a batch; state and outputs are arrays of N (one entry per run).

    Parameters
    ----------
    inputs : BatchInputs
    scenarios : list of Scenario
        Their wire parameters, hysteresis modes and start temperatures.
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
        self.reversal_T, self.reversal_xi = np.zeros(n), np.zeros(n)
        self.has_reversal, self._no_reversal = np.zeros(n), np.ones(n)   # 0/1 and 1/0
        self._stale = np.zeros(n, dtype=bool)         # minor-branch cache to refresh
        self._any_stale = False
        self._divisor, self._base, self._flat = np.ones(n), np.ones(n), np.ones(n)
        self._w = [np.empty(n) for _ in range(8)]      # work arrays
        self._pairs = [np.empty((2, n)) for _ in range(4)]   # work (2, N) arrays
        self._flags = [np.empty(n, dtype=bool) for _ in range(4)]
        # by direction: [heating; cooling] 0/1 masks, 1/tau_K, minor-branch selectors
        self._masks, self.inverse = np.empty((2, n)), np.empty(n)
        self._on_off, self._off_on = np.zeros((2, n)), np.zeros((2, n))
        self.M, self.xi_F_min, self.minus_energy = np.empty(n), np.empty(n), np.empty(n)
        self._centres = np.empty((2, n))               # [1/tau_K heating; cooling]
        self.inv_heating, self.inv_cooling = self._centres
        self._set(inputs.segment_row(0), np.arange(n))
        # state [xi_MF; xi_P; xi_M], and a spare the next step writes into
        self._state, self._spare = np.empty((3, n)), np.empty((3, n))
        self._state[0], self._state[1] = major_fractions(
            self.temperature, self.M, self.minus_energy, self.inv_heating)
        self._next_T = np.empty(n)
        self.xi_F, self.R = np.empty(n), np.empty(n)
        self._directions()
        self._evaluate()

    xi_MF = property(lambda self: self._state[0], doc="Mixed fraction xi_MF [1] per run.")
    xi_P = property(lambda self: self._state[1], doc="Parent fraction xi_P [1] per run.")
    xi_M = property(lambda self: self._state[2], doc="Martensite fraction xi_M [1] per run.")

    def _set(self, segments, runs):
        at, rows = self.inputs.constants, segments[runs]
        self.M[runs] = at["M"][rows, runs]
        self.xi_F_min[runs] = at["xi_F_min"][rows, runs]
        self.minus_energy[runs] = -at["energy_over_kB"][rows, runs]
        self.inv_heating[runs] = at["inv_centre_heating"][rows, runs]
        self.inv_cooling[runs] = at["inv_centre_cooling"][rows, runs]
        self._new_constants = True

    def set_segments(self, segments, previous):
        """Take the branch constants of the runs whose load segment changed (arrays of N)."""
        runs = np.flatnonzero(segments != previous)
        self._set(segments, runs)
        self._stale[runs] = True
        self._any_stale = True

    def _directions(self):
        """The 0/1 masks [heating; cooling] and 1/tau_K of each run's present direction."""
        masks = self._masks
        np.copyto(masks[0], self.heating)
        np.subtract(self.ones, masks[0], masks[1])
        pair = self._pairs[0]
        np.multiply(self._centres, masks, pair)
        np.add(pair[0], pair[1], self.inverse)     # exactly one term is nonzero
        self._new_constants = False

    def _refresh_minor(self, runs):
        """Cache, for ``runs`` (index array), the minor branch's reversal-point terms.

        A few runs (a reversal) one by one with the runtime's :func:`branch_fractions`,
        many (a load step) with :func:`major_fractions`: the same operations.
        """
        if runs.size > 8:
            self._refresh_many(runs)
            return
        for run in runs.tolist():
            heating, M = bool(self.heating[run]), float(self.M[run])
            xi_r = float(self.reversal_xi[run])
            centre = self.inv_heating[run] if heating else self.inv_cooling[run]
            xi_mf, xi_p = branch_fractions(float(self.reversal_T[run]), BranchConstants(
                M, float(self.xi_F_min[run]), -float(self.minus_energy[run]), float(centre), None))
            at_reversal = xi_mf if heating else xi_p
            flat = at_reversal < DENOMINATOR_FLOOR      # the branch stays at xi_r: value = base
            self._divisor[run] = 1.0 if flat else at_reversal
            self._flat[run] = 1.0 if flat else 0.0
            self._base[run] = xi_r if heating else M - xi_r

    def _refresh_many(self, runs):
        heating = self.heating[runs]
        inverse = np.where(heating, self.inv_heating[runs], self.inv_cooling[runs])
        M = self.M[runs]
        xi_mf, xi_p = major_fractions(self.reversal_T[runs], M, self.minus_energy[runs], inverse)
        at_reversal = np.where(heating, xi_mf, xi_p)
        flat = at_reversal < DENOMINATOR_FLOOR
        self._divisor[runs] = np.where(flat, 1.0, at_reversal)
        self._flat[runs] = flat
        self._base[runs] = np.where(heating, self.reversal_xi[runs], M - self.reversal_xi[runs])

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
        if self.any_continuous:
            self._minor_branches(before, turned if changed else None, fractions)
        self._spare, self._state = self._state, state
        self._next_T, self.temperature = before, after
        self._evaluate()

    def _minor_branches(self, before, turned, fractions):
        """Where a reversal is stored, replace the major-branch fractions by the minor branch."""
        mul, add = np.multiply, np.add
        if turned is not None:                          # reversals: direction changes
            reversed_ = np.logical_and(turned, self.continuous, out=turned)
            if np.count_nonzero(reversed_):
                runs = np.flatnonzero(reversed_)
                self.reversal_T[runs] = before[runs]
                self.reversal_xi[runs] = self.xi_MF[runs]
                self.has_reversal[runs] = 1.0
                self._no_reversal[runs] = 0.0
                self._refresh_minor(runs)
                mul(self._masks, self.has_reversal, self._on_off)
                mul(self._masks[::-1], self.has_reversal, self._off_on)
        if self._any_stale:                             # after a load step
            self._refresh_minor(np.flatnonzero(self._stale & (self.has_reversal > 0.0)))
            self._stale[:] = False
            self._any_stale = False
        # heating: xi_MF = clamp(xi_r L_h(T) / L_h(T_r)); cooling: xi_P = clamp((M - xi_r) ...)
        pair, values, minor = self._pairs[0], self._pairs[2], self._pairs[3]
        value, M = values[0], self.M
        mul(fractions, self._masks, pair)
        add(pair[0], pair[1], value)                    # xi_MF heating, xi_P cooling
        np.maximum(value, self._flat, out=value)        # flat: base * 1 / 1
        mul(self._base, value, value)
        np.divide(value, self._divisor, value)
        np.maximum(value, self.zeros, out=value)
        np.minimum(value, M, out=value)
        np.subtract(M, value, values[1])                # [value; M - value]
        # xi_MF = major (no reversal) or value (heating) or M - value (cooling); xi_P likewise.
        # Exactly one term is nonzero, so the sums are exact.
        mul(values, self._on_off, pair)
        add(pair[0], pair[1], minor[0])
        mul(values, self._off_on, pair)
        add(pair[0], pair[1], minor[1])
        mul(fractions, self._no_reversal, fractions)
        add(fractions, minor, fractions)

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
        """Wire length x [m] now: l_P xi_P + l_M xi_M + l_F xi_F."""
        return self.l_P * self.xi_P + self.l_M * self.xi_M + self.l_F * self.xi_F
