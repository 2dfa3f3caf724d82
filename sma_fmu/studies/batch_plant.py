"""N plants (:class:`~sma_fmu.runtime.plant.PlantStepper`) advanced in lock-step with numpy.

A second implementation of the scalar plant, operation by operation, so the two agree to
rounding (tests/test_batch.py binds them): the zero-order-hold thermal step, the direction
sgn(T+ - T), the major branch through the overflow-free logistic split of
:func:`~sma_fmu.runtime.constant_load.logistic_split`, and in mode "continuous" the minor
branches of :mod:`~sma_fmu.runtime.minor_loops`.

Speed: per step, each operation is one numpy call on arrays of N into a preallocated
output, and constants are arrays too (a Python float operand costs a conversion per call).
Where the scalar code branches, the batch selects with 0/1 float masks: a*1 + b*0 = a
exactly for finite a and b, and masked numpy copies cost several plain calls. What changes
only at a reversal or a load step (the minor branch's terms at the reversal point) is
cached and refreshed then.
"""
import numpy as np

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
        self.l_P, self.l_M, self.l_F = column("l_P"), column("l_M"), column("l_F")
        self.decay = inputs.decay
        self.rest = 1.0 - self.decay                   # 1 - e^(-h/tau_th), as thermal_step has it
        self.continuous = np.array([s.hysteresis_mode == "continuous" for s in scenarios])
        self.any_continuous = bool(self.continuous.any())
        self.ones, self.zeros = np.ones(n), np.zeros(n)
        self.halves, self.kelvin = np.full(n, 0.5), np.full(n, KELVIN_OFFSET)
        self.temperature = inputs.T_start.copy()
        self.heating = np.ones(n, dtype=bool)
        self.reversal_T, self.reversal_xi = np.zeros(n), np.zeros(n)
        self.has_reversal, self._no_reversal = np.zeros(n), np.ones(n)   # 0/1 and 1/0
        self._stale = np.zeros(n, dtype=bool)         # minor-branch cache to refresh
        self._divisor, self._base, self._flat = np.ones(n), np.ones(n), np.ones(n)
        self._w = [np.empty(n) for _ in range(20)]     # work arrays, and spare state buffers
        self._flags = [np.empty(n, dtype=bool) for _ in range(4)]
        self.M, self.xi_F_min, self.minus_energy = np.empty(n), np.empty(n), np.empty(n)
        self.inv_heating, self.inv_cooling = np.empty(n), np.empty(n)
        self._set(inputs.segment_row(0), np.arange(n))
        self.xi_MF, self.xi_P = major_fractions(self.temperature, self.M, self.minus_energy,
                                                self.inv_heating)
        self.xi_M, self.xi_F, self.R = np.empty(n), np.empty(n), np.empty(n)
        self._evaluate()

    def _set(self, segments, runs):
        at, rows = self.inputs.constants, segments[runs]
        self.M[runs] = at["M"][rows, runs]
        self.xi_F_min[runs] = at["xi_F_min"][rows, runs]
        self.minus_energy[runs] = -at["energy_over_kB"][rows, runs]
        self.inv_heating[runs] = at["inv_centre_heating"][rows, runs]
        self.inv_cooling[runs] = at["inv_centre_cooling"][rows, runs]

    def set_segments(self, segments, previous):
        """Take the branch constants of the runs whose load segment changed (arrays of N)."""
        runs = np.flatnonzero(segments != previous)
        self._set(segments, runs)
        self._stale[runs] = True

    def _refresh_minor(self, runs):
        """Cache, for ``runs`` (index array), the minor branch's reversal-point terms."""
        heating = self.heating[runs]
        inverse = np.where(heating, self.inv_heating[runs], self.inv_cooling[runs])
        M = self.M[runs]
        xi_mf, xi_p = major_fractions(self.reversal_T[runs], M, self.minus_energy[runs], inverse)
        at_reversal = np.where(heating, xi_mf, xi_p)
        flat = at_reversal < DENOMINATOR_FLOOR         # the branch stays at xi_r: value = base
        self._divisor[runs] = np.where(flat, 1.0, at_reversal)
        self._flat[runs] = flat
        self._base[runs] = np.where(heating, self.reversal_xi[runs], M - self.reversal_xi[runs])

    def step(self, power):
        """Advance every plant one step with ``power`` [W] (already >= 0) and its held load."""
        mul, add, sub, div, maximum = np.multiply, np.add, np.subtract, np.divide, np.maximum
        w, f = self._w, self._flags
        one = self.ones
        # w[14:20] are spare state buffers: T+, xi_MF, xi_P, and the three they replace
        before, after, xi_mf, xi_p = self.temperature, w[14], w[15], w[16]
        # thermal_step: T_room + (T - T_room) decay + K_th u (1 - decay)
        sub(before, self.T_room, w[0])
        mul(w[0], self.decay, w[0])
        add(self.T_room, w[0], after)
        mul(self.gain, power, w[1])
        mul(w[1], self.rest, w[1])
        add(after, w[1], after)
        # direction: heating if T+ > T, cooling if T+ < T, else unchanged
        up, keep, reversed_ = f[0], f[1], f[2]
        np.greater(after, before, up)
        np.less(after, before, keep)
        np.greater(self.heating, keep, keep)           # heating and not falling
        np.logical_or(up, keep, keep)
        if self.any_continuous:
            np.not_equal(keep, self.heating, reversed_)
            np.logical_and(reversed_, self.continuous, reversed_)
        self.heating, f[1] = keep, self.heating
        heating, cooling, inverse = w[2], w[3], w[4]   # 0/1 masks; 1/tau_K of the direction
        np.copyto(heating, keep)
        sub(one, heating, cooling)
        mul(self.inv_heating, heating, inverse)
        mul(self.inv_cooling, cooling, w[5])
        add(inverse, w[5], inverse)
        # major_fractions at T+
        x, e, denominator, positive, negative = w[5], w[6], w[7], w[8], w[9]
        add(after, self.kelvin, x)
        div(one, x, x)
        sub(inverse, x, x)
        np.greater(x, self.zeros, f[3])
        np.copyto(positive, f[3])                      # 1.0 where z > 0
        sub(one, positive, negative)
        np.abs(x, x)
        mul(self.minus_energy, x, x)
        np.exp(x, e)
        add(one, e, denominator)
        maximum(e, negative, out=negative)                # e if z > 0 else 1
        maximum(e, positive, out=positive)                # 1 if z > 0 else e
        mul(self.M, negative, xi_mf)
        div(xi_mf, denominator, xi_mf)
        mul(self.M, positive, xi_p)
        div(xi_p, denominator, xi_p)
        if self.any_continuous:
            self._minor_branches(before, reversed_, heating, cooling, xi_mf, xi_p)
        w[14], w[15], w[16] = before, self.xi_MF, self.xi_P
        self.temperature, self.xi_MF, self.xi_P = after, xi_mf, xi_p
        self._evaluate()

    def _minor_branches(self, before, reversed_, heating, cooling, xi_mf, xi_p):
        """Where a reversal is stored, replace the major-branch xi_mf, xi_p by the minor branch."""
        mul, add, w = np.multiply, np.add, self._w
        if np.count_nonzero(reversed_):
            runs = np.flatnonzero(reversed_)
            self.reversal_T[runs] = before[runs]
            self.reversal_xi[runs] = self.xi_MF[runs]
            self.has_reversal[runs] = 1.0
            self._no_reversal[runs] = 0.0
            self._stale[runs] = True
        if np.count_nonzero(self._stale):
            self._refresh_minor(np.flatnonzero(self._stale & (self.has_reversal > 0.0)))
            self._stale[:] = False
        # heating: xi_MF = clamp(xi_r L_h(T) / L_h(T_r)); cooling: xi_P = clamp((M - xi_r) ...)
        value, other, M = w[10], w[11], self.M
        mul(xi_mf, heating, value)
        mul(xi_p, cooling, other)
        add(value, other, value)
        np.maximum(value, self._flat, out=value)          # flat: base * 1 / 1
        mul(self._base, value, value)
        np.divide(value, self._divisor, value)
        np.maximum(value, self.zeros, out=value)
        np.minimum(value, M, out=value)
        np.subtract(M, value, other)
        # xi_MF = major (no reversal) or value (heating) or M - value (cooling); xi_P likewise.
        # Exactly one term is nonzero, so the sums are exact.
        on, off, term = w[12], w[13], w[0]
        mul(self.has_reversal, heating, on)
        mul(self.has_reversal, cooling, off)
        for fraction, first, second in ((xi_mf, value, other), (xi_p, other, value)):
            mul(fraction, self._no_reversal, fraction)
            mul(first, on, term)
            add(fraction, term, fraction)
            mul(second, off, term)
            add(fraction, term, fraction)

    def _evaluate(self):
        """R = R_P xi_P + R_M xi_M + R_F xi_F, xi_M = xi_MF/2, xi_F = xi_Fmin + xi_M."""
        mul, add, w = np.multiply, np.add, self._w[0]
        mul(self.halves, self.xi_MF, self.xi_M)
        add(self.xi_F_min, self.xi_M, self.xi_F)
        mul(self.R_P, self.xi_P, self.R)
        mul(self.R_M, self.xi_M, w)
        add(self.R, w, self.R)
        mul(self.R_F, self.xi_F, w)
        add(self.R, w, self.R)

    def length(self):
        """Wire length x [m] now: l_P xi_P + l_M xi_M + l_F xi_F."""
        return self.l_P * self.xi_P + self.l_M * self.xi_M + self.l_F * self.xi_F
