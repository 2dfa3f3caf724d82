"""The ``sma-fmu bound`` report: each scenario's controller beside the tracking bound.

For each scenario file: the RMSE of its controller (library path, metric of
:mod:`sma_fmu.cosim.metrics`) and the :class:`~.tracking_bound.TrackingBound` of its
reference, loads, hysteresis mode and driver limits. Scenarios that differ only in the
controller share one bound (it does not depend on the controller, nor on the sensor: the
bound is for a controller that knows the wire's state, which noise can only make worse).
With a noisy ``[sensor]`` the controller's RMSE is the median over
:data:`~sma_fmu.cosim.noise_seeds.NOISE_SEEDS` noise streams (the scenario's seed and the
next ones), each also listed. Writes ``bound.json`` and ``bound.md``.
"""
import hashlib

from sma_fmu.cosim.noise_seeds import NOISE_SEEDS, noise_seed_rmse
from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.files.json_output import json_text
from sma_fmu.files.output_folder import staged_folder

from .power_limit import PowerLimit
from .tracking_bound import SMOOTH_REVERSALS_PER_S, tracking_bound
from .tracking_problem import TrackingProblem

__all__ = ["problem_key", "bound_scenarios", "bound_markdown"]


def problem_key(scenario, limit=None):
    """A digest of what the bound depends on: reference, loads, mode, start, step, wire and
    the driver's ``limit`` (a :class:`~.power_limit.PowerLimit`)."""
    problem = TrackingProblem.from_scenario(scenario)
    digest = hashlib.sha256()
    for part in (problem.references, problem.step_loads, problem.weights):
        digest.update(part.tobytes())
    digest.update(repr((problem.mode, problem.T_start, problem.step_s,
                        sorted(problem.params.values().items()), limit)).encode())
    return digest.hexdigest()




def _ratio(value, bound):
    """``value / bound``, or None (printed n/a) where the bound is 0 or a rounding error's
    size beside the value (a benchmark of 1e-14 ohm gave a ratio of 1.1e13)."""
    return None if not bound > 1e-9 * abs(value) else value / bound


def _stroke_row(scenario, bound):
    """The controller's stroke RMSE [um] (one library run, the scenario's own sensor) beside
    the stroke's bound [um]."""
    from sma_fmu.cosim.loop import run_library
    from sma_fmu.cosim.metrics import scenario_metrics

    rmse = scenario_metrics(run_library(scenario).data, scenario)["stroke"]["rmse_um"]
    return {"rmse_um": rmse, "lower_bound_um": bound["lower_bound_um"],
            "achievable_um": bound["achievable_um"], "smooth_um": bound["smooth_um"],
            "rmse_over_achievable": _ratio(rmse, bound["achievable_um"]),
            "rmse_over_smooth": None if bound["smooth_um"] is None
            else _ratio(rmse, bound["smooth_um"])}


def bound_scenarios(paths, out_dir, power_cap=None, progress=print, current_A=None,
                    voltage_V=None, preview=False):
    """Bound every scenario file in ``paths``; write ``bound.json`` and ``bound.md``; return rows.

    ``power_cap`` P_cap [W] or None; ``current_A`` I_max [A] and ``voltage_V`` V_max [V], None:
    each scenario's ``[drive]`` limits; ``preview`` adds the receding-horizon benchmarks
    in mode "continuous" (:mod:`.preview_search`, minutes per scenario). All files are read before the first
    computation.
    """
    scenarios = [load_scenario(path) for path in paths]
    bounds, rows = {}, []
    with staged_folder(out_dir) as stage:
        for scenario in scenarios:
            limit = PowerLimit.of(power_cap, scenario, current_A, voltage_V)
            key = problem_key(scenario, limit)
            if key not in bounds:
                progress(f"bounding {scenario.name} ({scenario.hysteresis_mode}, "
                         f"{limit.describe()}) ...")
                bounds[key] = tracking_bound(scenario, limit, preview=preview)
            bound = bounds[key]
            rmse, per_seed = noise_seed_rmse(scenario)
            stroke = None if bound.stroke is None else _stroke_row(scenario, bound.stroke)
            controller = scenario.controller
            smooth = bound.smooth
            rows.append({"scenario": scenario.name, "controller": controller.kind,
                         "inverse": controller.inverse if controller.feedforward else None,
                         "rmse_ohm": rmse, "rmse_per_noise_seed_ohm": per_seed,
                         "sensor": None if scenario.sensor.ideal else vars(scenario.sensor),
                         "rmse_over_lower_bound": _ratio(rmse, bound.lower_bound_ohm),
                         "rmse_over_achievable": _ratio(rmse, bound.achievable.rmse_ohm),
                         "rmse_over_smooth": None if smooth is None else _ratio(rmse, smooth.rmse_ohm),
                         "bound": {k: v for k, v in bound.as_dict().items() if k != "scenario"},
                         **({} if stroke is None else {"stroke": stroke})})
        (stage / "bound.json").write_text(json_text(rows), encoding="utf-8")
        (stage / "bound.md").write_text(bound_markdown(rows), encoding="utf-8")
    return rows


def _number(value, digits=3):
    return "n/a" if value is None else f"{value:.{digits}f}"


def _limit_text(bound):
    return PowerLimit(bound["power_cap_W"], bound["current_limit_A"],
                      bound["voltage_limit_V"]).describe()


def bound_markdown(rows):
    """Markdown table of the rows of :func:`bound_scenarios`."""
    limits = sorted({_limit_text(row["bound"]) for row in rows})
    noisy = any(row["rmse_per_noise_seed_ohm"] for row in rows)
    lines = ["# Tracking bound", "",
             f"RMSE of e = R - R_ref over the metric window, ohm; power P >= 0 W, "
             f"{'; '.join(limits) or 'unlimited'} (the driver's limit at the wire's R). The best "
             "any controller can reach lies between the lower bound and the best benchmark; "
             f"'smooth' is the best benchmark with at most {SMOOTH_REVERSALS_PER_S:g} temperature "
             "reversals per second." + (f" With sensor noise, RMSE is the median over "
                                        f"{NOISE_SEEDS} noise seeds (the bound is noise-free)."
                                        if noisy else ""),
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
    strokes = [row for row in rows if "stroke" in row]
    if strokes:
        lines += ["", "Stroke (a stroke reference mapped to R_ref through the model): RMSE of the "
                  "stroke x_0 - x against the stroke reference, um; the lower bound is the "
                  "reference's distance to the stroke the wire gives at the load, the benchmarks' "
                  "strokes are their powers replayed through the plant.", "",
                  "| scenario | controller | stroke RMSE | lower bound | best benchmark | "
                  "smooth benchmark | RMSE / best | RMSE / smooth |",
                  "|---|---|---:|---:|---:|---:|---:|---:|"]
        for row in strokes:
            stroke = row["stroke"]
            lines.append(f"| {row['scenario']} | {row['controller']} | "
                         f"{_number(stroke['rmse_um'], 1)} | {_number(stroke['lower_bound_um'], 1)} | "
                         f"{_number(stroke['achievable_um'], 1)} | {_number(stroke['smooth_um'], 1)} | "
                         f"{_number(stroke['rmse_over_achievable'], 1)} | "
                         f"{_number(stroke['rmse_over_smooth'], 1)} |")
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
