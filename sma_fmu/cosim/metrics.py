"""Tracking metrics of a run (spec section 11): RMSE, max |e|, IAE of e_k = R_k - R_ref(t_k).

Over all samples k = 0 ... n with t_k >= the scenario's ``[analysis] metrics_start_s``
(2 s for the paper's 30-s runs: the start-up transient is left out), and per load
segment (the same window applied inside each segment).

Every step counts, block by block (:class:`StreamingMetrics`): a run of any length
needs no whole series, and what a run records to its file (``output_interval_s``) does
not change its metrics.

Reachability: where R_ref(t_k) lies outside the band (R_hot(f_k), R_cold(f_k)) the wire can
reach at the load of that sample (:func:`sma_fmu.runtime.reachable_band.reachable_band`),
no controller can track it. The metrics give the fraction of the window where that is
so, the metrics over the reachable rest, the intervals (whole run) and a warning.

Ambient: passive cooling brings the wire to T_room at best, so once heated through its
transformation it returns at most to R_amb(f), its cooling major branch at T_room
(:func:`ambient_edges`). Where R_ref lies inside the band but above R_amb(f) (a wire whose
cooling transformation lies at or below the ambient), no controller with a heater alone can
track it after the first heating: ``above_ambient_fraction`` of the window, and a warning.
For the shipped wires R_amb lies within 0.006 ohm of R_cold, so this says nothing there.

Stroke: a scenario whose reference is a stroke adds ``stroke``, the error of the stroke
x_0 - x against the stroke reference, in micrometres (RMSE, max |e|, IAE, per load segment).
"""
import math

import numpy as np

from sma_fmu.cosim.loop import ROWS_PER_CHUNK
from sma_fmu.runtime.constant_load import constant_load_resistance
from sma_fmu.runtime.constants import COOLING
from sma_fmu.runtime.reachable_band import reachable_band
from sma_fmu.runtime.signals import is_stroke

__all__ = ["EMPTY_METRICS", "error_metrics", "band_edges", "ambient_edges", "stroke_metrics",
           "unreachable_samples", "ambient_warning",
           "unreachable_intervals", "reachability_warning", "metric_windows", "assemble_metrics",
           "scenario_metrics", "ErrorSums", "StreamingMetrics"]

_LISTED_INTERVALS = 4  # a warning names at most this many intervals, then counts the rest
EMPTY_METRICS = {"rmse_ohm": None, "max_abs_ohm": None, "iae_ohm_s": None, "samples": 0}
"""The metrics of a window without samples (copy it before changing it)."""


def error_metrics(errors, step_size):
    """{"rmse_ohm", "max_abs_ohm", "iae_ohm_s", "samples"} of an error array [ohm]."""
    errors = np.asarray(errors, dtype=float)
    if errors.size == 0:
        return dict(EMPTY_METRICS)
    with np.errstate(over="ignore", invalid="ignore"):  # a diverged run gives inf, reported as such
        return {
            "rmse_ohm": float(np.sqrt(np.mean(errors ** 2))),
            "max_abs_ohm": float(np.max(np.abs(errors))),
            "iae_ohm_s": float(step_size * np.sum(np.abs(errors))),
            "samples": int(errors.size),
        }


def _per_load(loads, value, count):
    """``count`` arrays of the numbers ``value(load)`` gives (a tuple of ``count``) at each
    load [kg] of ``loads``, computed once per distinct load (loads are piecewise constant)."""
    loads = np.asarray(loads, dtype=float)
    if loads.size and loads[0] == loads[-1] and (loads == loads[0]).all():  # one load (mostly)
        return tuple(np.full_like(loads, number) for number in value(float(loads[0])))
    columns = tuple(np.empty_like(loads) for _ in range(count))
    ordered = np.sort(loads)   # the distinct loads (np.unique would import numpy.ma: 40 ms)
    for load in ordered[np.concatenate(([True], ordered[1:] != ordered[:-1]))]:
        for column, number in zip(columns, value(float(load))):
            column[loads == load] = number
    return columns


def band_edges(loads, params):
    """Arrays (R_hot, R_cold) [ohm] of the reachable band at each load [kg] of ``loads``."""
    return _per_load(loads, lambda load: reachable_band(load, params), 2)


def ambient_edges(loads, params):
    """Array R_amb(f) [ohm] at each load [kg] of ``loads``: the resistance on the cooling
    major branch at T_room, the most a wire heated through its transformation gets back by
    passive cooling (module docstring)."""
    return _per_load(loads, lambda load: (constant_load_resistance(
        params.T_room, load, COOLING, params),), 1)[0]


def unreachable_samples(references, loads, params):
    """Boolean arrays (below, above): R_ref [ohm] at or below R_hot(f), at or above R_cold(f).

    ``references`` and ``loads`` [kg] are arrays of samples.
    """
    references = np.asarray(references, dtype=float)
    hot, cold = band_edges(loads, params)
    return references <= hot, references >= cold


def unreachable_intervals(times, below, above):
    """[[first, last, side], ...]: runs of consecutive unreachable samples, times in s.

    ``side`` is "below R_hot" or "above R_cold".
    """
    intervals = []
    for mask, side in ((below, "below R_hot"), (above, "above R_cold")):
        if not mask.any():
            continue
        edges = np.diff(np.concatenate(([0], mask.astype(np.int8), [0])))
        starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
        intervals += [[float(times[a]), float(times[b]), side] for a, b in zip(starts, ends)]
    return sorted(intervals)


def reachability_warning(intervals, fraction):
    """One warning naming the intervals where R_ref was unreachable, or None if there are none.

    ``fraction`` [1] is the share of the metric window that was unreachable.
    """
    if not intervals:
        return None
    listed = ", ".join(f"{a:g}-{b:g} s ({side})" for a, b, side in intervals[:_LISTED_INTERVALS])
    more = len(intervals) - _LISTED_INTERVALS
    return (f"R_ref leaves the band the wire can reach at the current load (below the fully "
            f"hot or above the fully cold resistance) in {len(intervals)} interval(s) between "
            f"t = {intervals[0][0]:g} s and {intervals[-1][1]:g} s: {listed}"
            f"{f' and {more} more' if more > 0 else ''}; {100.0 * fraction:.1f} % of the "
            f"metric window; no controller can track it there")


def ambient_warning(fraction, first_time, edges, params):
    """The warning for R_ref above the ambient end (module docstring), or None.

    ``fraction`` [1] of the window, from ``first_time`` [s]; ``edges`` {load [kg]: R_amb
    [ohm]} where it happened."""
    if not fraction > 0.0:   # none, or no window (nan)
        return None
    where = ", ".join(f"{edge:.4g} ohm at {load:g} kg" for load, edge in sorted(edges.items()))
    return (f"R_ref lies above what passive cooling reaches in {100.0 * fraction:.1f} % of the "
            f"metric window (from t = {first_time:g} s): cooled to thermal.T_room = "
            f"{params.T_room:g} degC, a wire heated through its transformation returns only to "
            f"{where} (its cooling branch at T_room), so no heater-driven controller tracks it "
            f"there; set thermal.T_room to the bench's ambient, or keep the reference below "
            f"that resistance")


def metric_windows(times, scenario):
    """Boolean masks over ``times`` [s]: (the metrics window, [one per load segment]).

    The window is t >= ``[analysis] metrics_start_s`` (to 1e-9 steps); a segment's mask is
    the window within [start, end) of the segment, the last segment including the final
    sample. The segments are those of ``scenario.load.segments(stop_time_s)``, in order.
    """
    times = np.asarray(times, dtype=float)
    window = times >= scenario.analysis.metrics_start_s - 1e-9 * scenario.step_s
    segments = []
    for start, end, _ in scenario.load.segments(scenario.stop_time_s):
        last = end >= scenario.stop_time_s  # the last segment includes the final sample
        segments.append(window & (times >= start - 1e-9)
                        & ((times <= end + 1e-9) if last else (times < end - 1e-9)))
    return window, segments


def stroke_metrics(overall, segments):
    """The ``stroke`` record [um] from :class:`ErrorSums` of stroke errors [m]: overall and
    one RMSE per load segment."""
    def in_um(metrics):
        return {"rmse_um": None if metrics["rmse_ohm"] is None else 1e6 * metrics["rmse_ohm"],
                "max_abs_um": None if metrics["max_abs_ohm"] is None
                else 1e6 * metrics["max_abs_ohm"],
                "iae_um_s": None if metrics["iae_ohm_s"] is None else 1e6 * metrics["iae_ohm_s"],
                "samples": metrics["samples"]}
    return {**in_um(overall), "segments_rmse_um": [in_um(m)["rmse_um"] for m in segments]}


def assemble_metrics(scenario, *, overall, segments, saturated_fraction, clamped_fraction,
                     unreachable_fraction, reachable, intervals, stroke=None, ambient=None):
    """The metrics record of one run of ``scenario``, ready for JSON, from its parts.

    ``overall``, ``reachable`` and each of ``segments`` (one per load segment, in order) are
    :func:`error_metrics` dicts; the fractions [1] are shares of the metrics window;
    ``intervals`` are the :func:`unreachable_intervals` of the whole run; ``stroke`` the
    :func:`stroke_metrics` of a stroke reference (None: none); ``ambient`` (fraction [1],
    first time [s], {load: R_amb}) of R_ref above the ambient end (None: not computed, as
    in the batch engine: ``above_ambient_fraction`` is None). Adds the header
    (scenario, controller, the wire: its parameter file and digest, and the compensator's
    model where a study gives it other values, window), each segment's times and load, and
    the warning.
    """
    metrics_start = scenario.analysis.metrics_start_s
    warnings = [reachability_warning(intervals, unreachable_fraction)]
    if ambient is not None:
        warnings.append(ambient_warning(*ambient, scenario.params))
    model = scenario.compensator_parameter_set
    return {
        "scenario": scenario.name,
        "controller": scenario.controller.kind,
        "inverse": scenario.controller.inverse if scenario.controller.feedforward else None,
        "hysteresis_mode": scenario.hysteresis_mode,
        "wire": scenario.parameter_set.record(),
        **({} if model is None else {"compensator_wire": model.record()}),
        "window": f"t >= {metrics_start:g} s",
        "metrics_start_s": metrics_start,
        "overall": overall,
        "segments": [{"start_s": start, "end_s": end, "load_kg": load, **metrics}
                     for (start, end, load), metrics in
                     zip(scenario.load.segments(scenario.stop_time_s), segments)],
        "saturated_fraction": saturated_fraction,
        "clamped_fraction": clamped_fraction,
        "unreachable_fraction": unreachable_fraction,
        "reachable": reachable,
        "unreachable_intervals_s": intervals,
        "above_ambient_fraction": None if ambient is None else ambient[0],
        "warnings": [warning for warning in warnings if warning is not None],
        **({} if stroke is None else {"stroke": stroke}),
    }


class ErrorSums:
    """Running sums of an error signal [ohm]: sum of squares, of magnitudes, the largest
    magnitude, the count; :meth:`metrics` gives the :func:`~.metrics.error_metrics` record."""

    def __init__(self):
        self.squares = self.magnitudes = 0.0
        self.largest = -math.inf
        self.count = 0

    def add(self, errors):
        """Count the errors [ohm] of one block (an array)."""
        if errors.size == 0:
            return
        self.take(self.terms(errors))

    @staticmethod
    def terms(errors):
        """(sum of squares, sum of magnitudes, largest magnitude, count) of a non-empty array
        of errors [ohm]: what :meth:`add` counts, for :meth:`take` (one block's errors may
        count in several sums)."""
        with np.errstate(over="ignore", invalid="ignore"):  # a diverged run gives inf, as such
            magnitudes = np.abs(errors)
            return (float(np.sum(np.square(errors))), float(np.sum(magnitudes)),
                    np.max(magnitudes), int(errors.size))

    def take(self, terms):
        """Count a block's :meth:`terms`."""
        squares, magnitudes, largest, count = terms
        with np.errstate(over="ignore", invalid="ignore"):
            self.squares += squares
            self.magnitudes += magnitudes
            self.largest = float(np.maximum(self.largest, largest))  # NaN propagates
        self.count += count

    def metrics(self, step_size):
        """{"rmse_ohm", "max_abs_ohm", "iae_ohm_s", "samples"}; ``step_size`` [s]."""
        if self.count == 0:
            return dict(EMPTY_METRICS)
        return {"rmse_ohm": math.sqrt(self.squares / self.count), "max_abs_ohm": self.largest,
                "iae_ohm_s": step_size * self.magnitudes, "samples": self.count}


class StreamingMetrics:
    """The metrics of one run of ``scenario``, fed block by block (:meth:`update`).
    :attr:`COLUMNS_READ`: the only columns :meth:`update` reads (a master may leave the
    others unrecorded, as the C master of a sweep does; the sweep's test compares its
    metrics with those of whole rows, so a column read but not listed fails it)."""

    COLUMNS_READ = ("t", "R", "R_ref", "load", "saturated", "P", "stroke")

    def __init__(self, scenario):
        self.scenario = scenario
        self.overall, self.reachable = ErrorSums(), ErrorSums()
        self.segments = [ErrorSums() for _ in scenario.load.segments(scenario.stop_time_s)]
        self._strokes = (scenario.reference.strokes
                         if is_stroke(scenario.reference) else None)
        self.stroke = ErrorSums()                      # stroke errors [m], the window's
        self.stroke_segments = [ErrorSums() for _ in self.segments]
        self.window = self.saturated = self.clamped = self.unreachable = self.above_ambient = 0
        self.intervals = []
        self._ambient_first, self._ambient_edges = None, {}   # (time [s], {load: R_amb})
        self._last_time = None   # the time of the last row seen [s]

    def update(self, block):
        """Count one block of consecutive rows (a structured array)."""
        if block.size == 0:
            return
        t = block["t"]
        error = block["R"] - block["R_ref"]
        window, segments = metric_windows(t, self.scenario)
        below, above = unreachable_samples(block["R_ref"], block["load"], self.scenario.params)
        unreachable = below | above
        # the usual block lies wholly in the window, one segment and the reachable band: its
        # errors are counted once and the same sums go to each (the same numbers, to the bit)
        whole = bool(window.all())
        reachable = not unreachable.any()
        terms = ErrorSums.terms(error) if whole else None
        if whole:
            self.overall.take(terms)
        else:
            self.overall.add(error[window])
        for sums, inside in zip(self.segments, segments):
            if whole and inside.all():
                sums.take(terms)
            elif inside.any():
                sums.add(error[inside])
        if whole and reachable:
            self.reachable.take(terms)
        else:
            self.reachable.add(error[window & ~unreachable])
        inside = (lambda column: column) if whole else (lambda column: column[window])  # noqa: E731
        self.window += int(block.size) if whole else int(np.count_nonzero(window))
        self.saturated += int(np.count_nonzero(inside(block["saturated"])))
        # the final row's P is NaN, never 0: counting it changes nothing (see result)
        self.clamped += int(np.count_nonzero(inside(block["P"]) == 0.0))
        self.unreachable += 0 if reachable else int(np.count_nonzero(unreachable[window]))
        self._count_above_ambient(block, window, unreachable)
        self._join(unreachable_intervals(t, below, above), float(t[0]))
        self._last_time = float(t[-1])
        if self._strokes is not None:
            stroke_error = block["stroke"] - np.array(self._strokes(t.tolist()))
            self.stroke.add(stroke_error[window])
            for sums, inside in zip(self.stroke_segments, segments):
                sums.add(stroke_error[inside])

    def _count_above_ambient(self, block, window, unreachable):
        """Count the window's samples with R_ref inside the band but above R_amb(f)."""
        edge = ambient_edges(block["load"], self.scenario.params)
        above = (block["R_ref"] > edge) & window & ~unreachable
        if not above.any():
            return
        self.above_ambient += int(np.count_nonzero(above))
        if self._ambient_first is None:
            self._ambient_first = float(block["t"][np.argmax(above)])
        for load, value in zip(block["load"][above].tolist(), edge[above].tolist()):
            self._ambient_edges.setdefault(load, value)

    def _join(self, intervals, first_time):
        """Add a block's unreachable intervals, joining one that goes on from the last block."""
        for interval in intervals:
            start, _, side = interval
            if start == first_time and self._last_time is not None:
                joined = next((known for known in self.intervals
                               if known[2] == side and known[1] == self._last_time), None)
                if joined is not None:
                    joined[1] = interval[1]
                    continue
            self.intervals.append(interval)

    def result(self):
        """The metrics record (:func:`~.metrics.assemble_metrics`)."""
        step = self.scenario.step_s
        window = self.window
        return assemble_metrics(
            self.scenario,
            overall=self.overall.metrics(step),
            segments=[sums.metrics(step) for sums in self.segments],
            saturated_fraction=self.saturated / window if window else math.nan,
            clamped_fraction=self.clamped / (window - 1) if window > 1 else None,
            unreachable_fraction=self.unreachable / window if window else math.nan,
            reachable=self.reachable.metrics(step),
            intervals=sorted(self.intervals),
            stroke=None if self._strokes is None else stroke_metrics(
                self.stroke.metrics(step), [sums.metrics(step) for sums in self.stroke_segments]),
            ambient=(self.above_ambient / window if window else math.nan, self._ambient_first,
                     self._ambient_edges))


def scenario_metrics(data, scenario):
    """Metrics of one run: over the metrics window and per load segment, ready for JSON.

    ``data`` goes through :class:`StreamingMetrics` in the blocks a loop streams
    (:data:`~sma_fmu.cosim.loop.ROWS_PER_CHUNK` rows), so a run's metrics are the same
    whether its series was kept whole or streamed.
    """
    metrics = StreamingMetrics(scenario)
    for first in range(0, max(len(data), 1), ROWS_PER_CHUNK):
        metrics.update(data[first:first + ROWS_PER_CHUNK])
    return metrics.result()
