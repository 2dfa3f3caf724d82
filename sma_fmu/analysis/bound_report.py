"""The ``sma-fmu bound`` report: each scenario's controller beside the tracking bound.

For each scenario file: the RMSE of its controller (library path, metric of
:mod:`sma_fmu.cosim.metrics`) and the :class:`~.tracking_bound.TrackingBound` of its
reference, loads and hysteresis mode. Scenarios that differ only in the controller share
one bound (it does not depend on the controller). Writes ``bound.json`` and ``bound.md``.
"""
import hashlib

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.files.json_output import json_text
from sma_fmu.files.output_folder import staged_folder

from .tracking_bound import SMOOTH_REVERSALS_PER_S, tracking_bound
from .tracking_problem import TrackingProblem

__all__ = ["problem_key", "bound_scenarios", "bound_markdown"]


def problem_key(scenario):
    """A digest of what the bound depends on: reference, loads, mode, start, step and wire."""
    problem = TrackingProblem.from_scenario(scenario)
    digest = hashlib.sha256()
    for part in (problem.references, problem.step_loads, problem.weights):
        digest.update(part.tobytes())
    digest.update(repr((problem.mode, problem.T_start, problem.step_s,
                        sorted(problem.params.values().items()))).encode())
    return digest.hexdigest()


def _ratio(value, bound):
    return None if not bound > 0.0 else value / bound


def bound_scenarios(paths, out_dir, power_cap=None, progress=print):
    """Bound every scenario file in ``paths``; write ``bound.json`` and ``bound.md``; return rows.

    ``power_cap`` P_max [W] or None. All files are read before the first computation.
    """
    scenarios = [load_scenario(path) for path in paths]
    bounds, rows = {}, []
    with staged_folder(out_dir) as stage:
        for scenario in scenarios:
            key = problem_key(scenario)
            if key not in bounds:
                progress(f"bounding {scenario.name} ({scenario.hysteresis_mode}) ...")
                bounds[key] = tracking_bound(scenario, power_cap)
            bound = bounds[key]
            metrics = scenario_metrics(run_library(scenario).data, scenario)
            rmse = metrics["overall"]["rmse_ohm"]
            smooth = bound.smooth
            rows.append({"scenario": scenario.name, "controller": metrics["controller"],
                         "inverse": metrics["inverse"], "rmse_ohm": rmse,
                         "rmse_over_lower_bound": _ratio(rmse, bound.lower_bound_ohm),
                         "rmse_over_achievable": _ratio(rmse, bound.achievable.rmse_ohm),
                         "rmse_over_smooth": None if smooth is None else _ratio(rmse, smooth.rmse_ohm),
                         "bound": {k: v for k, v in bound.as_dict().items() if k != "scenario"}})
        (stage / "bound.json").write_text(json_text(rows), encoding="utf-8")
        (stage / "bound.md").write_text(bound_markdown(rows), encoding="utf-8")
    return rows


def _number(value, digits=3):
    return "n/a" if value is None else f"{value:.{digits}f}"


def bound_markdown(rows):
    """Markdown table of the rows of :func:`bound_scenarios`."""
    cap = rows[0]["bound"]["power_cap_W"] if rows else None
    lines = ["# Tracking bound", "",
             f"RMSE of e = R - R_ref over the metric window, ohm; power 0 W <= P "
             f"{'unlimited' if cap is None else f'<= {cap:g} W'}. The best any controller can "
             "reach lies between the lower bound and the best benchmark; 'smooth' is the best "
             f"benchmark with at most {SMOOTH_REVERSALS_PER_S:g} temperature reversals per second.",
             "", "| scenario | mode | controller | RMSE | lower bound | best benchmark (peak W, "
             "reversals/s) | smooth benchmark (peak W, reversals/s) | RMSE / lower bound | "
             "RMSE / smooth |", "|---|---|---|---:|---:|---:|---:|---:|---:|"]
    for row in rows:
        bound = row["bound"]
        controller = row["controller"] + ("" if row["inverse"] in (None, "major")
                                          else f" ({row['inverse']} inverse)")
        lines.append(f"| {row['scenario']} | {bound['hysteresis_mode']} | {controller} | "
                     f"{_number(row['rmse_ohm'])} | {_number(bound['lower_bound_ohm'])} | "
                     f"{_benchmark(bound['achievable'])} | {_benchmark(bound['smooth'])} | "
                     f"{_number(row['rmse_over_lower_bound'], 1)} | "
                     f"{_number(row['rmse_over_smooth'], 1)} |")
    methods = {(r["bound"]["hysteresis_mode"], r["bound"]["lower_bound_method"]) for r in rows}
    lines += [""] + [f"- {mode}: lower bound by {method}." for mode, method in sorted(methods)]
    benchmarks = {(r["bound"]["hysteresis_mode"], b["method"]) for r in rows
                  for b in (r["bound"]["achievable"], r["bound"]["smooth"]) if b}
    lines += [f"- {mode} benchmark: {method}, replayed through the plant."
              for mode, method in sorted(benchmarks)]
    return "\n".join(lines) + "\n"


def _benchmark(benchmark):
    if benchmark is None:
        return "n/a"
    return (f"{benchmark['rmse_ohm']:.3f} ({benchmark['peak_W']:.0f}, "
            f"{benchmark['reversals_per_s']:.0f})")
