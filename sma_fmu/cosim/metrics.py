"""Tracking metrics of a run (spec section 11): RMSE, max |e|, IAE of e_k = R_k - R_ref(t_k).

Over all samples k = 0 ... n with t_k >= the scenario's ``[analysis] metrics_start_s``
(2 s for the paper's 30-s runs: the start-up transient is left out), and per load
segment (the same window applied inside each segment).
"""
import numpy as np

__all__ = ["error_metrics", "scenario_metrics"]


def error_metrics(errors, step_size):
    """{"rmse_ohm", "max_abs_ohm", "iae_ohm_s", "samples"} of an error array [ohm]."""
    errors = np.asarray(errors, dtype=float)
    if errors.size == 0:
        return {"rmse_ohm": None, "max_abs_ohm": None, "iae_ohm_s": None, "samples": 0}
    with np.errstate(over="ignore", invalid="ignore"):  # a diverged run gives inf, reported as such
        return {
            "rmse_ohm": float(np.sqrt(np.mean(errors ** 2))),
            "max_abs_ohm": float(np.max(np.abs(errors))),
            "iae_ohm_s": float(step_size * np.sum(np.abs(errors))),
            "samples": int(errors.size),
        }


def scenario_metrics(data, scenario):
    """Metrics of one run: overall (t >= 2 s) and per load segment, ready for JSON."""
    t = data["t"]
    error = data["R"] - data["R_ref"]
    metrics_start = scenario.analysis.metrics_start_s
    window = t >= metrics_start - 1e-9 * scenario.step_s
    segments = []
    for start, end, load in scenario.load.segments(scenario.stop_time_s):
        last = end >= scenario.stop_time_s  # the last segment includes the final sample
        inside = window & (t >= start - 1e-9) & ((t <= end + 1e-9) if last else (t < end - 1e-9))
        segments.append({"start_s": start, "end_s": end, "load_kg": load,
                         **error_metrics(error[inside], scenario.step_s)})
    return {
        "scenario": scenario.name,
        "controller": scenario.controller.kind,
        "hysteresis_mode": scenario.hysteresis_mode,
        "window": f"t >= {metrics_start:g} s",
        "metrics_start_s": metrics_start,
        "overall": error_metrics(error[window], scenario.step_s),
        "segments": segments,
        "saturated_fraction": float(np.mean(data["saturated"][window])),
        "clamped_fraction": (float(np.mean(data["P"][window][:-1] == 0.0))
                             if window.sum() > 1 else None),
    }
