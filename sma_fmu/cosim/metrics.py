"""Tracking metrics of a run (spec section 11): RMSE, max |e|, IAE of e_k = R_k - R_ref(t_k).

Over all samples k = 0 ... n with t_k >= the scenario's ``[analysis] metrics_start_s``
(2 s for the paper's 30-s runs: the start-up transient is left out), and per load
segment (the same window applied inside each segment).

Reachability: where R_ref(t_k) lies outside the band (R_hot(f_k), R_cold(f_k)) the wire can
reach at the load of that sample (:func:`sma_fmu.runtime.reachable_band.reachable_band`),
no controller can track it. The metrics give the fraction of the window where that is
so, the metrics over the reachable rest, the intervals (whole run) and a warning.
"""
import numpy as np

from sma_fmu.runtime.reachable_band import reachable_band

__all__ = ["EMPTY_METRICS", "error_metrics", "band_edges", "unreachable_samples",
           "unreachable_intervals", "reachability_warning", "metric_windows", "assemble_metrics",
           "scenario_metrics"]

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


def band_edges(loads, params):
    """Arrays (R_hot, R_cold) [ohm] of the reachable band at each load [kg] of ``loads``.

    The band is computed once per distinct load (loads are piecewise constant).
    """
    loads = np.asarray(loads, dtype=float)
    hot, cold = np.empty_like(loads), np.empty_like(loads)
    for load in np.unique(loads):
        band = reachable_band(float(load), params)
        hot[loads == load], cold[loads == load] = band.hot, band.cold
    return hot, cold


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


def assemble_metrics(scenario, *, overall, segments, saturated_fraction, clamped_fraction,
                     unreachable_fraction, reachable, intervals):
    """The metrics record of one run of ``scenario``, ready for JSON, from its parts.

    ``overall``, ``reachable`` and each of ``segments`` (one per load segment, in order) are
    :func:`error_metrics` dicts; the fractions [1] are shares of the metrics window;
    ``intervals`` are the :func:`unreachable_intervals` of the whole run. Adds the header
    (scenario, controller, window), each segment's times and load, and the warning.
    """
    metrics_start = scenario.analysis.metrics_start_s
    warning = reachability_warning(intervals, unreachable_fraction)
    return {
        "scenario": scenario.name,
        "controller": scenario.controller.kind,
        "inverse": scenario.controller.inverse if scenario.controller.feedforward else None,
        "hysteresis_mode": scenario.hysteresis_mode,
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
        "warnings": [] if warning is None else [warning],
    }


def scenario_metrics(data, scenario):
    """Metrics of one run: over the metrics window and per load segment, ready for JSON."""
    t = data["t"]
    error = data["R"] - data["R_ref"]
    window, segments = metric_windows(t, scenario)
    below, above = unreachable_samples(data["R_ref"], data["load"], scenario.params)
    unreachable = below | above
    return assemble_metrics(
        scenario,
        overall=error_metrics(error[window], scenario.step_s),
        segments=[error_metrics(error[inside], scenario.step_s) for inside in segments],
        saturated_fraction=float(np.mean(data["saturated"][window])),
        clamped_fraction=(float(np.mean(data["P"][window][:-1] == 0.0))
                          if window.sum() > 1 else None),
        unreachable_fraction=float(np.mean(unreachable[window])),
        reachable=error_metrics(error[window & ~unreachable], scenario.step_s),
        intervals=unreachable_intervals(t, below, above))
