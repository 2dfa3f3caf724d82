"""Tracking metrics of a batch, accumulated chunk by chunk: no run's time series is kept.

The same record as :func:`sma_fmu.cosim.metrics.scenario_metrics`: the windows are its
:func:`~sma_fmu.cosim.metrics.metric_windows` on t_k = k h, turned into index ranges; the
reachable band comes from :func:`~sma_fmu.runtime.reachable_band.reachable_band` per run
and load segment; the record (and its warning) from
:func:`~sma_fmu.cosim.metrics.assemble_metrics`. Sums run over chunks instead of a stored
series, so they agree to rounding (tests/studies/test_batch.py binds the two). A stroke
scenario's ``stroke`` record comes from the wire's lengths x_k the loop hands over with each
chunk: the error (x_0 - x_k) - stroke_ref(t_k) [m], as the library's
(tests/studies/test_batch_stroke.py binds the two).
"""
import math

import numpy as np

from sma_fmu.cosim.metrics import EMPTY_METRICS, assemble_metrics, metric_windows, stroke_metrics
from sma_fmu.runtime.signals import is_stroke

__all__ = ["MetricsAccumulator"]

_SIDES = ("below R_hot", "above R_cold")


def _index_range(mask):
    """[first, stop) of a contiguous boolean mask (t_k is increasing, so windows are ranges)."""
    where = np.flatnonzero(mask)
    if where.size == 0:
        return 0, 0
    if where[-1] - where[0] + 1 != where.size:
        raise AssertionError("a metrics window is not contiguous")
    return int(where[0]), int(where[-1]) + 1


class _Totals:
    """Sum of e^2, sum of |e|, max |e| and count per run over rows [first, stop) where
    ``keep`` (a (rows, N) mask, or None for all) holds."""

    def __init__(self, first, stop, size):
        self.first, self.stop = first, stop
        self.squares, self.absolute = np.zeros(size), np.zeros(size)
        self.largest, self.count = np.zeros(size), np.zeros(size, dtype=np.int64)

    def add(self, start, absolute, squares, columns, keep=None):
        """Add rows of |e| and e^2 (c, N) from step ``start``; returns what was added, or None.

        ``columns``: the runs (an index array, or a slice of all).
        """
        low, high = max(self.first, start), min(self.stop, start + absolute.shape[0])
        if low >= high:
            return None
        rows = slice(low - start, high - start)
        part, square = absolute[rows, columns], squares[rows, columns]
        if keep is not None:
            chosen = keep[rows, columns]
            part, square = np.where(chosen, part, 0.0), np.where(chosen, square, 0.0)
            count = np.count_nonzero(chosen, axis=0)
        else:
            count = high - low
        added = (np.sum(square, axis=0), np.sum(part, axis=0), np.max(part, axis=0), count)
        self.include(added, columns)
        return added

    def include(self, added, columns):
        """Add sums returned by :meth:`add` (of the same rows) to ``columns``."""
        squares, absolute, largest, count = added
        self.squares[columns] += squares
        self.absolute[columns] += absolute
        self.largest[columns] = np.maximum(self.largest[columns], largest)
        self.count[columns] += count

    def metrics(self, run, step_s):
        count = int(self.count[run])
        if count == 0:
            return dict(EMPTY_METRICS)
        return {"rmse_ohm": math.sqrt(float(self.squares[run]) / count),
                "max_abs_ohm": float(self.largest[run]),
                "iae_ohm_s": float(step_s * self.absolute[run]), "samples": count}


class MetricsAccumulator:
    """Metrics of every run of a batch from chunks of e_k = R_k - R_ref(t_k), P_k and flags.

    ``inputs`` is the batch's :class:`~sma_fmu.studies.batch.inputs.BatchInputs`;
    ``scenarios`` give the load segments and the metrics window.
    """

    def __init__(self, inputs, scenarios):
        self.scenarios, self.inputs, self.step_s = scenarios, inputs, inputs.step_s
        t, size = inputs.times, inputs.size
        self.groups, self._group_of = [], {}
        keys = {}
        for run, scenario in enumerate(scenarios):
            start = scenario.analysis.metrics_start_s
            key = (start, tuple((a, b) for a, b, _ in scenario.load.segments(scenario.stop_time_s)))
            keys.setdefault(key, []).append(run)
        for runs in keys.values():      # the same window and segments: the first run's
            window, segments = metric_windows(t, scenarios[runs[0]])
            parts = [_Totals(*_index_range(inside), size) for inside in segments]
            window = _index_range(window)
            self._group_of.update((run, len(self.groups)) for run in runs)
            columns = slice(None) if runs == list(range(size)) else np.array(runs)
            self.groups.append({"columns": columns, "window": window, "segments": parts,
                                "overall": _Totals(*window, size),
                                "reachable": _Totals(*window, size),
                                "stroke": _Totals(*window, size),
                                "stroke_segments": [_Totals(*_index_range(inside), size)
                                                    for inside in segments]})
        self.saturated, self.clamped = np.zeros(size), np.zeros(size)
        self.unreachable = np.zeros(size)
        self._inside = {side: np.zeros(size, dtype=bool) for side in _SIDES}   # carried over
        self._opened = {side: {} for side in _SIDES}
        self.intervals = [[] for _ in range(size)]
        self._stroke_references(scenarios, t)

    def _stroke_references(self, scenarios, times):
        """The stroke runs (:attr:`stroke_runs`) and their references [m] at t_k, one column
        per reference object (the runs of a tuning share theirs)."""
        columns, index, self._start_length = {}, [], None
        for scenario in scenarios:
            reference = scenario.reference
            if is_stroke(reference):
                index.append(columns.setdefault(id(reference), (len(columns), reference))[0])
        self.stroke_runs = np.array([run for run, scenario in enumerate(scenarios) if is_stroke(
            scenario.reference)], dtype=int)
        self._stroke_column = np.array(index, dtype=int)
        self._stroke_reference = np.array(
            [[reference.stroke(time) for time in times.tolist()]
             for _, reference in columns.values()]).T if columns else None

    def _add_stroke(self, start, lengths):
        """Rows k = start ... of the wire's lengths x [m] (c, N): the stroke errors' sums."""
        runs = self.stroke_runs
        if start == 0:
            self._start_length = lengths[0, runs].copy()
        stop = start + lengths.shape[0]
        errors = np.zeros(lengths.shape)
        errors[:, runs] = ((self._start_length - lengths[:, runs])
                           - self._stroke_reference[start:stop][:, self._stroke_column])
        absolute = np.abs(errors)
        squares = absolute * absolute
        for group in self.groups:
            group["stroke"].add(start, absolute, squares, group["columns"])
            for part in group["stroke_segments"]:
                part.add(start, absolute, squares, group["columns"])

    def add(self, start, errors, power, saturated, lengths=None):
        """Rows k = start ... of e [ohm], applied power P [W] (nan at k = n) and flags, (c, N);
        ``lengths``: the wire's x [m] at the same rows (needed when :attr:`stroke_runs`)."""
        stop = start + errors.shape[0]
        if self.stroke_runs.size:
            self._add_stroke(start, lengths)
        bands = self.inputs.unreachable(start, stop)    # None: all reachable, usually
        if bands is None:
            below = above = np.zeros(errors.shape, dtype=bool) if any(
                inside.any() for inside in self._inside.values()) else None
            anywhere = False
        else:
            below, above = bands
            outside = below | above
            anywhere = bool(outside.any())     # usually not: then reachable = overall here
        absolute = np.abs(errors)              # each once per chunk, for every sum below
        squares = absolute * absolute
        for group in self.groups:
            runs = group["columns"]
            overall = group["overall"].add(start, absolute, squares, runs)
            if anywhere:
                group["reachable"].add(start, absolute, squares, runs, keep=~outside)
            elif overall is not None:          # the same rows, all of them reachable
                group["reachable"].include(overall, runs)
            for part in group["segments"]:
                part.add(start, absolute, squares, runs)
            first, last = group["window"]
            low, high = max(first, start), min(last, stop)
            if low < high:
                rows = slice(low - start, high - start)
                self.saturated[runs] += np.count_nonzero(saturated[rows, runs], axis=0)
                self.clamped[runs] += np.count_nonzero(power[rows, runs] == 0.0, axis=0)
                if anywhere:
                    self.unreachable[runs] += np.count_nonzero(outside[rows, runs], axis=0)
        for side, mask in zip(_SIDES, (below, above)):
            if anywhere or self._inside[side].any():
                self._track(side, start, mask)

    def _track(self, side, start, mask):
        """Runs of consecutive unreachable samples, as unreachable_intervals finds them."""
        rows = np.vstack([self._inside[side], mask]).astype(np.int8)
        change = np.diff(rows, axis=0)
        times = self.inputs.times
        opened = self._opened[side]
        for row, run in zip(*np.nonzero(change)):
            k = start + int(row)
            if change[row, run] > 0:
                opened[int(run)] = k
            else:
                self.intervals[run].append([float(times[opened.pop(int(run))]),
                                            float(times[k - 1]), side])
        self._inside[side] = mask[-1].copy()

    def metrics(self, run):
        """The :func:`~sma_fmu.cosim.metrics.scenario_metrics` record of run ``run``."""
        scenario = self.scenarios[run]
        group = self.groups[self._group_of[run]]
        count = group["window"][1] - group["window"][0]
        intervals = list(self.intervals[run])
        for side in _SIDES:                     # still open at the last sample
            if run in self._opened[side]:
                intervals.append([float(self.inputs.times[self._opened[side][run]]),
                                  float(self.inputs.times[-1]), side])
        intervals.sort()
        return assemble_metrics(
            scenario,
            overall=group["overall"].metrics(run, self.step_s),
            segments=[part.metrics(run, self.step_s) for part in group["segments"]],
            saturated_fraction=float(self.saturated[run] / count) if count else math.nan,
            clamped_fraction=float(self.clamped[run] / (count - 1)) if count > 1 else None,
            unreachable_fraction=float(self.unreachable[run] / count) if count else math.nan,
            reachable=group["reachable"].metrics(run, self.step_s),
            intervals=intervals,
            stroke=stroke_metrics(group["stroke"].metrics(run, self.step_s),
                                  [part.metrics(run, self.step_s)
                                   for part in group["stroke_segments"]])
            if run in self.stroke_runs else None)
