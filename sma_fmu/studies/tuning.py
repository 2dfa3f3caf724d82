"""``sma-fmu tune``: the gains that minimise each scenario's RMSE, found with the batch engine.

Per scenario, scipy's ``differential_evolution`` (vectorized: each generation is one
batch, :func:`~sma_fmu.studies.batch.run_batch`) searches Kp and Ki, and for the
feedforward controllers also the phase-lag times alpha and beta, within :data:`BOUNDS`,
for the least RMSE of R - R_ref over the scenario's metrics window (the same RMSE as
``sma-fmu run``; t >= 2 s for the paper's 30-s runs). The best gains are run once more on the scalar library path, and that
RMSE is the one reported. Writes ``NAME/controller.toml`` (a ``[controller]`` table that
pastes into the scenario), ``report.json`` and ``report.md`` (the controllers ranked at
the scenario's own gains and at each controller's tuned gains).
"""
import dataclasses
import json
import math
import time
from datetime import datetime, timezone

import numpy as np
from scipy.optimize import differential_evolution

from sma_fmu.console import progress
from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.scenario import CONTROLLERS, load_scenario
from sma_fmu.files.json_output import json_text
from sma_fmu.files.output_folder import staged_folder
from sma_fmu.fmi.loop.gains import GAIN_KEYS
from sma_fmu.studies.batch import run_batch, unsupported_reason
from sma_fmu.studies.overrides import StudyError, template

__all__ = ["BOUNDS", "TUNED", "tune_scenario", "controller_snippet", "run_tuning",
           "ranking_markdown"]

# search ranges; units: Kp [W/ohm], Ki [W/(ohm.s)], alpha and beta [s]
BOUNDS = {"Kp": (0.0, 5.0), "Ki": (0.0, 20.0), "alpha": (0.0, 3.0), "beta": (0.02, 1.5)}
TUNED = {"pi": ("Kp", "Ki"), "pi+ff-fixed": ("Kp", "Ki", "alpha", "beta"),
         "pi+ff-adaptive": ("Kp", "Ki", "alpha", "beta")}
_FAILED_RMSE = 1e6   # what a run that fails costs the optimiser [ohm]


def _with_gains(scenario, names, values):
    return dataclasses.replace(scenario, controller=dataclasses.replace(
        scenario.controller, **{name: float(v) for name, v in zip(names, values)}))


def _rmse(metrics):
    value = None if metrics is None else metrics["overall"]["rmse_ohm"]
    return _FAILED_RMSE if value is None or not math.isfinite(value) else value


def tune_scenario(scenario, seed=1, generations=30, population=12):
    """Tune one scenario's controller; returns a JSON-ready record (values, RMSE, effort)."""
    reason = unsupported_reason(scenario)
    if reason:
        raise StudyError(f"tune needs the batch engine: {reason}")
    names = TUNED[scenario.controller.kind]
    evaluations = 0

    def cost(candidates):                      # (D, S) -> (S,)
        nonlocal evaluations
        batch = [_with_gains(scenario, names, column) for column in np.atleast_2d(candidates).T]
        evaluations += len(batch)
        return np.array([_rmse(run.metrics) for run in run_batch(batch)])

    began = time.perf_counter()
    start = [getattr(scenario.controller, name) for name in names]
    with progress.bar(generations, f"tuning {scenario.name}", unit="generation") as shown:
        result = differential_evolution(
            cost, [BOUNDS[name] for name in names], maxiter=generations, popsize=population,
            rng=seed, polish=False, vectorized=True, updating="deferred", tol=1e-4,
            x0=np.clip(start, [BOUNDS[n][0] for n in names], [BOUNDS[n][1] for n in names]),
            callback=lambda *_: shown.update(1) and None)
    seconds = time.perf_counter() - began
    best = _with_gains(scenario, names, result.x)
    tuned = scenario_metrics(run_library(best).data, best)   # the reported RMSE: scalar path
    given = scenario_metrics(run_library(scenario).data, scenario)
    return {"scenario": scenario.name, "group": scenario.group,
            "controller": scenario.controller.kind, "inverse": scenario.controller.inverse,
            "hysteresis_mode": scenario.hysteresis_mode,
            "tuned": {name: float(v) for name, v in zip(names, result.x)},
            "given": {name: float(v) for name, v in zip(names, start)},
            "window": given["window"],
            "rmse_ohm": {"tuned": tuned["overall"]["rmse_ohm"],
                         "given": given["overall"]["rmse_ohm"],
                         "tuned_batch": float(result.fun)},
            "bounds": {name: list(BOUNDS[name]) for name in names},
            "at_bound": [name for name, v in zip(names, result.x)
                         if min(v - BOUNDS[name][0], BOUNDS[name][1] - v)
                         < 1e-3 * (BOUNDS[name][1] - BOUNDS[name][0])],
            "optimiser": {"method": "scipy differential_evolution (vectorized, batch engine)",
                          "seed": seed, "generations": int(result.nit),
                          "evaluations": evaluations, "message": str(result.message),
                          "seconds": seconds}}


def controller_snippet(record):
    """The tuned gains as a ``[controller]`` TOML table that pastes into the scenario."""
    lines = [f"# sma-fmu tune {record['scenario']} ({datetime.now(timezone.utc).date()}): "
             f"RMSE {record['rmse_ohm']['tuned']:.4f} ohm, against "
             f"{record['rmse_ohm']['given']:.4f} ohm at the scenario's gains",
             "[controller]", f"kind = {json.dumps(record['controller'])}"]
    if record.get("inverse", "major") != "major":
        lines.append(f"inverse = {json.dumps(record['inverse'])}")
    lines += [f"{GAIN_KEYS[name]} = {value!r}" for name, value in record["tuned"].items()]
    return "\n".join(lines) + "\n"


def _label(record):
    """The controller's column: its kind, with a non-default inverse in parentheses."""
    inverse = record.get("inverse", "major")
    return record["controller"] + ("" if inverse == "major" else f" ({inverse})")


def ranking_markdown(records):
    """Per group of scenarios with every controller: RMSE [ohm] and order, given vs tuned gains.

    Columns: the three controllers, then any other inverse present (a group without it
    shows "-" there and ranks the rest).
    """
    groups, labels = {}, list(CONTROLLERS)
    for record in records:
        label = _label(record)
        if label not in labels:
            labels.append(label)
        groups.setdefault((record["group"], record["hysteresis_mode"]), {})[label] = record
    windows = ", ".join(sorted({record["window"] for record in records}))
    lines = ["# Tuned gains", "", f"RMSE of R - R_ref over {windows} [ohm], on the library path.",
             "", "| scenario | mode | gains | " + " | ".join(labels) + " | ranking, best first |",
             "|---|---|---|" + "---:|" * len(labels) + "---|"]
    for (group, mode), members in groups.items():
        if not set(CONTROLLERS) <= set(members):
            continue
        for gains in ("given", "tuned"):
            rmse = {c: members[c]["rmse_ohm"][gains] for c in labels if c in members}
            order = " < ".join(sorted(rmse, key=rmse.get))
            lines.append(f"| {group} | {mode} | {gains} | " +
                         " | ".join(f"{rmse[c]:.3f}" if c in rmse else "-" for c in labels)
                         + f" | {order} |")
    lines += ["", "| scenario | RMSE given | RMSE tuned | tuned values (* at a bound) |",
              "|---|---:|---:|---|"]
    for record in records:
        values = ", ".join(f"{name} = {value:.4g}{'*' if name in record['at_bound'] else ''}"
                           for name, value in record["tuned"].items())
        lines.append(f"| {record['scenario']} | {record['rmse_ohm']['given']:.3f} | "
                     f"{record['rmse_ohm']['tuned']:.3f} | {values} |")
    return "\n".join(lines) + "\n"


def _with_stop_time(scenario, stop_time_s):
    """``scenario`` lasting ``stop_time_s`` [s], checked as in a file (whole steps, at most
    MAX_STEPS, the [analysis] windows inside the run)."""
    try:
        return template(scenario).scenario({"scenario.stop_time_s": float(stop_time_s)})
    except StudyError as error:
        raise StudyError(f"--stop-time {stop_time_s!r}: {error}") from None


def run_tuning(paths, out_dir, seed=1, generations=30, population=12, stop_time_s=None,
               progress=print):
    """Tune every scenario file in ``paths``; write snippets and reports; return the records."""
    scenarios = [load_scenario(p) for p in paths]
    if stop_time_s is not None and not stop_time_s > 0.0:
        raise StudyError(f"--stop-time {stop_time_s!r}: must be > 0 s")
    if stop_time_s is not None:
        scenarios = [_with_stop_time(s, stop_time_s) for s in scenarios]
    records = []
    for index, scenario in enumerate(scenarios, start=1):
        progress(f"[{index}/{len(scenarios)}] tuning {scenario.name} "
                 f"({', '.join(TUNED[scenario.controller.kind])}) ...")
        record = tune_scenario(scenario, seed, generations, population)
        progress(f"    RMSE {record['rmse_ohm']['given']:.4f} -> {record['rmse_ohm']['tuned']:.4f}"
                 f" ohm: " + ", ".join(f"{k} = {v:.4g}" for k, v in record["tuned"].items()))
        records.append(record)
    with staged_folder(out_dir) as stage:
        for record in records:
            (stage / record["scenario"]).mkdir()
            (stage / record["scenario"] / "controller.toml").write_text(
                controller_snippet(record), encoding="utf-8")
        (stage / "report.json").write_text(json_text(records), encoding="utf-8")
        (stage / "report.md").write_text(ranking_markdown(records), encoding="utf-8")
    return records
