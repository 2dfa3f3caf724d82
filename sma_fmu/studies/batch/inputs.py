"""What a batch of closed loops knows before it starts: per-run constants and open-loop signals.

Nothing here depends on the plant's state, so it is computed once per run (constants) or
once per chunk of time steps (signals), never per step. Every formula is the scalar
runtime's own, called per run: :func:`~sma_fmu.runtime.constant_load.branch_constants`
per load segment and direction, :func:`~sma_fmu.runtime.thermal.step_decay`,
:meth:`ReferenceSignal.value` at t_k = k h (as :func:`sma_fmu.cosim.loop.run_loop` samples
it; once per distinct reference). The load segment at t_k is the lookup of
:meth:`LoadProfile.value` (bisect_right, with its tolerance) done by ``numpy.searchsorted``. Runs whose constants cannot be built
(a load beyond the model's range) are listed in :attr:`BatchInputs.failures`. The runs with
a PWM drive and their drivers' frequencies and peak powers are listed too.
"""
import warnings

import numpy as np

from sma_fmu.runtime.constant_load import branch_constants
from sma_fmu.runtime.constants import COOLING, HEATING
from sma_fmu.runtime.reachable_band import band_of_branch
from sma_fmu.runtime.signals import is_stroke
from sma_fmu.runtime.thermal import step_decay

__all__ = ["BatchInputs", "CONSTANT_FIELDS", "LOAD_TOLERANCE_S"]

LOAD_TOLERANCE_S = 1e-9   # LoadProfile.value's: a switching time this close counts as reached
CONSTANT_FIELDS = ("M", "xi_F_min", "energy_over_kB", "inv_centre_heating", "inv_centre_cooling",
                   "energy_cooling", "M1", "M2", "energy2_heating", "energy2_cooling",
                   "inv2_heating", "inv2_cooling", "length_M", "length_F")
# energy_over_kB is the heating branch's (nu_h); the rest are the optional model terms
# (runtime/model_terms.py): 0 for the second stage of a one-stage wire (M1 = M, M2 = 0, so
# the two-stage sum equals the one-stage split exactly) and l_M, l_F without strain terms


def _row(heating, cooling, params):
    """The CONSTANT_FIELDS of one load: the heating and cooling BranchConstants."""
    two = heating.w2 != 0.0
    return (heating.M, heating.xi_F_min, heating.energy_over_kB, heating.inv_centre_K,
            cooling.inv_centre_K, cooling.energy_over_kB,
            heating.M1 if two else heating.M, heating.M2 if two else 0.0,
            heating.energy2_over_kB if two else 0.0, cooling.energy2_over_kB if two else 0.0,
            heating.inv_centre2_K if two else 0.0, cooling.inv_centre2_K if two else 0.0,
            params.l_M if heating.length_M is None else heating.length_M,
            params.l_F if heating.length_F is None else heating.length_F)


def _reference_key(reference):
    """What makes two scenarios' R_ref the same: a resistance reference's kind and settings;
    a stroke reference's R_ref depends on its wire and loads too, so it is shared with none."""
    if is_stroke(reference):
        return "stroke", id(reference)
    settings = tuple(sorted((key, tuple(value) if isinstance(value, list) else value)
                            for key, value in reference.settings.items()))
    return reference.kind, settings


def _reference_direction(values):
    """d_ref of :class:`FeedforwardStepper` for a reference sequence: True while heating.

    Falling R_ref -> heating, rising -> cooling, equal keeps the last; starts heating.
    """
    change = np.zeros(values.size, dtype=bool)
    change[1:] = values[1:] != values[:-1]
    falling = np.ones(values.size, dtype=bool)
    falling[1:] = values[1:] < values[:-1]
    last = np.maximum.accumulate(np.where(change, np.arange(values.size), 0))  # last change <= k
    return np.where(last > 0, falling[last], True)


class BatchInputs:
    """Constants and signals of ``scenarios`` (all with the same step and number of steps).

    Attributes
    ----------
    size : int
        Number of runs N.
    step_s : float
        Communication step h [s].
    steps : int
        Number of steps n.
    times : numpy.ndarray
        t_k = k h [s], k = 0 ... n.
    constants, compensator_constants : dict of numpy.ndarray
        :data:`CONSTANT_FIELDS` -> (S + 1, N) of the plant's and of the compensator's
        parameters: row s < S is load segment s of each run (padded with its last
        segment); row S (compensator) the fixed compensator's model load.
    change_steps : list of int
        Steps k >= 1 at which some run's load segment changes, sorted.
    failures : dict
        Run index -> message for runs whose constants could not be built.
    pwm_runs : numpy.ndarray
        Indices of the runs whose ``[drive]`` is "pwm", ascending (empty when none is).
    pwm_frequency, pwm_peak : numpy.ndarray
        Their drivers' frequencies [Hz] and peak powers [W], one entry per ``pwm_runs``.
    """

    def __init__(self, scenarios):
        first = scenarios[0]
        self.size = len(scenarios)
        self.step_s, self.steps = first.step_s, first.steps
        for scenario in scenarios:
            if scenario.step_s != self.step_s or scenario.steps != self.steps:
                raise ValueError(
                    f"a batch needs one step and duration: {scenario.name} has step "
                    f"{scenario.step_s!r} s x {scenario.steps} steps, {first.name} "
                    f"{self.step_s!r} s x {self.steps} steps")
        self.times = np.array([k * self.step_s for k in range(self.steps + 1)])
        self.failures = {}
        self._references(scenarios)
        self._segments(scenarios)
        self._constants(scenarios)
        self._bands(scenarios)
        self.T_start = np.array([s.T_start for s in scenarios])
        self.decay = np.array([step_decay(self.step_s, s.params.tau_th) for s in scenarios])
        self._drives(scenarios)

    def _drives(self, scenarios):
        drives = [(run, s.drive) for run, s in enumerate(scenarios) if s.drive.pwm]
        self.pwm_runs = np.array([run for run, _ in drives], dtype=int)
        self.pwm_frequency = np.array([drive.frequency_Hz for _, drive in drives], dtype=float)
        self.pwm_peak = np.array([drive.peak_W for _, drive in drives], dtype=float)

    def _references(self, scenarios):
        groups, number, index = {}, {}, []
        for scenario in scenarios:
            key = _reference_key(scenario.reference)
            if key not in groups:
                number[key] = len(groups)
                groups[key] = np.array([scenario.reference.value(t) for t in self.times.tolist()])
            index.append(number[key])
        self.reference_values = np.column_stack(list(groups.values()))     # (n + 1, G)
        self.reference_heating = np.column_stack(
            [_reference_direction(values) for values in groups.values()])   # (n + 1, G)
        self.reference_group = np.array(index)

    def _segments(self, scenarios):
        groups, number, index = {}, {}, []
        for scenario in scenarios:
            times = tuple(scenario.load.times)
            if times not in groups:
                number[times] = len(groups)
                # LoadProfile.value: values[bisect_right(times, t + tolerance) - 1]
                groups[times] = np.searchsorted(np.array(times), self.times + LOAD_TOLERANCE_S,
                                                side="right") - 1
            index.append(number[times])
        self.segment_values = np.column_stack(list(groups.values()))        # (n + 1, L)
        self.segment_group = np.array(index)
        self.segment_count = max(len(times) for times in groups)
        changes = set()
        for values in groups.values():
            changes.update((np.flatnonzero(values[1:] != values[:-1]) + 1).tolist())
        self.change_steps = sorted(changes)
        self.loads = np.array([s.load.values + [s.load.values[-1]] * (self.segment_count
                               - len(s.load.values)) for s in scenarios]).T  # (S, N)

    def _constants(self, scenarios):
        self._heating = {}     # (id(parameters), load) -> heating BranchConstants of the plants
        self.constants = self._table(scenarios, lambda s: s.params, lambda s: [], self._heating)
        fixed = lambda s: ([s.controller.model_load] if s.controller.feedforward  # noqa: E731
                           and not s.controller.adapt_to_load else [])
        self.compensator_constants = self._table(
            [s if s.controller.feedforward else None for s in scenarios],
            lambda s: s.compensator_params, fixed)
        self.model_row = self.segment_count

    def _bands(self, scenarios):
        """R_hot, R_cold [ohm] of the plant's wire per load segment and run: (S, N) each.

        :func:`~sma_fmu.runtime.reachable_band.band_of_branch` of the plants' heating
        branches (:func:`reachable_band`'s); NaN where the constants could not be built.
        """
        values = np.full((self.size, self.segment_count, 2), np.nan)
        nan = (np.nan, np.nan)
        for run, (scenario, loads) in enumerate(zip(scenarios, self.loads.T.tolist())):
            params, memo = scenario.params, self._heating
            values[run] = [band_of_branch(memo[key], params) if key in memo else nan
                           for key in ((id(params), load) for load in loads)]
        self.band_hot = np.ascontiguousarray(values[:, :, 0].T)
        self.band_cold = np.ascontiguousarray(values[:, :, 1].T)
        with warnings.catch_warnings():                 # all NaN: no fast path
            warnings.simplefilter("ignore", RuntimeWarning)
            self._hot_max, self._cold_min = np.nanmax(self.band_hot), np.nanmin(self.band_cold)

    def unreachable(self, start, stop):
        """(below, above), (c, N) each: R_ref(t_k) <= R_hot(f_k), R_ref(t_k) >= R_cold(f_k);
        None when every R_ref of the chunk lies inside every run's band."""
        values = self.reference_values[start:stop]      # (c, references)
        if values.min() > self._hot_max and values.max() < self._cold_min:
            return None
        reference = self.references(start, stop)
        rows = stop - start if self.changes_within(start, stop) else 1   # else one row broadcasts
        segments = np.broadcast_to(self.segments(start, start + rows), (rows, self.size))
        columns = np.arange(self.size)
        return (reference <= self.band_hot[segments, columns],
                reference >= self.band_cold[segments, columns])

    def _table(self, scenarios, params_of, extra_loads, heating=None):
        """{field: (S + 1, N)} of branch constants per load segment (+ extra loads) and run.

        ``heating``, a dict, collects the heating branches' BranchConstants.
        """
        values = np.full((self.size, self.segment_count + 1, len(CONSTANT_FIELDS)), np.nan)
        memo = {}     # (parameters, load) -> row: runs that share a wire share the work
        for run, (scenario, loads) in enumerate(zip(scenarios, self.loads.T.tolist())):
            if scenario is None:
                continue
            params, rows = params_of(scenario), []
            try:
                for load in loads + extra_loads(scenario):
                    key = (id(params), load)
                    if key not in memo:
                        branch = branch_constants(load, HEATING, params)
                        if heating is not None:
                            heating[key] = branch
                        cooling = branch_constants(load, COOLING, params)
                        memo[key] = _row(branch, cooling, params)
                    rows.append(memo[key])
            except ValueError as error:
                self.failures[run] = str(error)
            if rows:
                values[run, :len(rows)] = rows
        return {name: np.ascontiguousarray(values[:, :, i].T)
                for i, name in enumerate(CONSTANT_FIELDS)}

    def changes_within(self, start, stop):
        """True when some run's load segment changes at a step start < k < stop."""
        return any(start < k < stop for k in self.change_steps)

    def chunk_rows(self, start, stop, table, group, runs=None):
        """Rows ``start`` ... ``stop - 1`` of a per-group (n + 1, G) ``table``, per run.

        Returns (c, N), or (c, len(runs)) for the index array ``runs``; with one group,
        (c, 1), which broadcasts.
        """
        if table.shape[1] == 1:
            return table[start:stop]
        return table[start:stop][:, group if runs is None else group[runs]]

    def references(self, start, stop, runs=None):
        """R_ref(t_k) [ohm] for k = start ... stop - 1, per run (see :meth:`chunk_rows`)."""
        return self.chunk_rows(start, stop, self.reference_values, self.reference_group, runs)

    def reference_heating_rows(self, start, stop, runs=None):
        """The compensator's reference direction (True: heating) per step and run."""
        return self.chunk_rows(start, stop, self.reference_heating, self.reference_group, runs)

    def segments(self, start, stop, runs=None):
        """Load segment index per step and run."""
        return self.chunk_rows(start, stop, self.segment_values, self.segment_group, runs)

    def segment_row(self, k):
        """Load segment index of every run at step ``k``: (N,)."""
        return np.broadcast_to(self.segments(k, k + 1)[0], (self.size,))

    def load_rows(self, start, stop):
        """f(t_k) [kg] per step and run: (c, N)."""
        return self.loads[self.segments(start, stop), np.arange(self.size)]
