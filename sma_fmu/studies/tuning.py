"""``sma-fmu tune``: the gains that minimise each scenario's RMSE, found with the batch engine.

Per scenario, scipy's ``differential_evolution`` (vectorized: each generation is one
batch, :func:`~sma_fmu.studies.batch.run_batch`) searches Kp and Ki, and for the
feedforward controllers also the phase-lag times alpha and beta, within :data:`BOUNDS`,
for the least RMSE of R - R_ref over the scenario's metrics window (the same RMSE as
``sma-fmu run``; t >= 2 s for the paper's 30-s runs), or, for a stroke scenario, the least
RMSE of its stroke [um] (:mod:`sma_fmu.studies.criterion`: the default there, or chosen).
The best gains are run once more on the scalar library path, and that RMSE is the one
reported. Writes ``NAME/controller.toml`` (a ``[controller]`` table that pastes into the
scenario), ``report.json`` and ``report.md`` (:mod:`sma_fmu.studies.tuning_report`: the
controllers ranked at the scenario's own gains and at each controller's tuned gains).
:func:`tune_jointly` (``--joint``) seeks one gain set for several scenarios.

A scenario the batch engine does not implement (the shaped compensator) is tuned on the
scalar library path instead, one run at a time (about 1.5 s per 30-s run: keep
``generations`` and ``population`` small); a shaped compensator has no phase-lag filter, so
only Kp and Ki are searched.

With a :class:`~sma_fmu.studies.robust.RobustCriterion` (``--robust``) the score of a set of
gains is a quantile of the RMSEs over Monte Carlo draws of noise stream and wire, the same
draws for every candidate (:mod:`sma_fmu.studies.robust`). Every record also carries the
margins of the linearised loop at the given and the tuned gains
(:mod:`sma_fmu.studies.margins`) and, for a noisy scenario, the median RMSE over five noise
streams on the nominal wire at the tuned gains (:mod:`sma_fmu.cosim.noise_seeds`).
"""
import dataclasses
import time
from collections import namedtuple

import numpy as np
from scipy.optimize import OptimizeResult, differential_evolution

from sma_fmu.console import progress
from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.noise_seeds import noise_seed_rmse
from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.files.json_output import json_text
from sma_fmu.files.output_folder import staged_folder
from sma_fmu.studies.batch import run_batch, unsupported_reason
from sma_fmu.studies.criterion import UNITS, criterion_rmse, scenario_criterion, stroke_fields
from sma_fmu.studies.margins import loop_margins
from sma_fmu.studies.overrides import StudyError, template
from sma_fmu.studies.robust import draw_scenarios, robust_value
from sma_fmu.studies.tuning_report import (SHAPED_KEYS, controller_snippet, print_record,
                                           ranking_markdown)
from sma_fmu.runtime.signals import is_stroke

__all__ = ["BOUNDS", "TUNED", "tune_scenario", "tune_jointly", "controller_snippet", "run_tuning",
           "ranking_markdown"]

# search ranges; units: Kp [W/ohm], Ki [W/(ohm.s)], alpha and beta [s]
BOUNDS = {"Kp": (0.0, 5.0), "Ki": (0.0, 20.0), "alpha": (0.0, 3.0), "beta": (0.02, 1.5)}
TUNED = {"pi": ("Kp", "Ki"), "pi+ff-fixed": ("Kp", "Ki", "alpha", "beta"),
         "pi+ff-adaptive": ("Kp", "Ki", "alpha", "beta")}
_LibraryRun = namedtuple("_LibraryRun", "metrics")             # a library run, as a batch's


def _with_gains(scenario, names, values):
    return dataclasses.replace(scenario, controller=dataclasses.replace(
        scenario.controller, **{name: float(v) for name, v in zip(names, values)}))


def _robust_record(scenario, best, names, start, robust):
    """The draws' RMSEs (scalar path) at the given and the tuned gains, and the score: R's
    [ohm], and for a stroke scenario the stroke's [um] beside."""
    record = robust.as_dict()
    criteria = ("resistance", "stroke") if is_stroke(scenario.reference) else ("resistance",)
    tuned = [getattr(best.controller, n) for n in names]
    for label, values in (("given", start), ("tuned", tuned)):
        metrics = [scenario_metrics(run_library(draw).data, draw) for draw in
                   (_with_gains(d, names, values) for d in draw_scenarios(scenario, robust))]
        for name in criteria:
            rmses = [criterion_rmse(m, name) for m in metrics]
            record[f"rmse_{label}_{UNITS[name]}"] = rmses
            record[f"score_{label}_{UNITS[name]}"] = float(robust_value(rmses, robust.quantile))
    return record


def _tuned_names(scenario):
    """The controller fields searched: :data:`TUNED`, without the filter's alpha and beta for
    a shaped compensator (it does not use them)."""
    names = TUNED[scenario.controller.kind]
    return names[:2] if scenario.controller.shaping != "none" else names


def _library_runs(scenarios):
    """What :func:`run_batch` gives (objects with ``metrics``), one library run at a time."""
    return [_LibraryRun(scenario_metrics(run_library(scenario).data, scenario))
            for scenario in scenarios]


class _Objective:
    """A scenario's score of candidate gains (minimised): the criterion's RMSE, or its
    quantile over the robust draws; one batch per call (the library path where the batch
    engine lacks an option: :attr:`reason`)."""

    def __init__(self, scenario, names, criterion, robust):
        self.reason = unsupported_reason(scenario)
        self.runs = _library_runs if self.reason else run_batch
        self.names, self.criterion = names, criterion
        self.draws = [scenario] if robust is None else draw_scenarios(scenario, robust)
        self.quantile = 0.5 if robust is None else robust.quantile
        self.evaluations = 0

    def __call__(self, candidates):              # (D, S) -> (S,); (D,) is one candidate
        candidates = np.asarray(candidates, dtype=float)
        columns = candidates.T if candidates.ndim == 2 else [candidates]
        batch = [_with_gains(draw, self.names, column)
                 for column in columns for draw in self.draws]
        self.evaluations += len(batch)
        rmses = np.array([criterion_rmse(run.metrics, self.criterion) for run in self.runs(batch)])
        return robust_value(rmses.reshape(-1, len(self.draws)), self.quantile)


def _search(cost, names, start, seed, generations, population, label):
    """scipy's differential evolution of ``cost`` from ``start``: (result, seconds)."""
    began = time.perf_counter()
    with progress.bar(generations, f"tuning {label}", unit="generation") as shown:
        result = differential_evolution(
            cost, [BOUNDS[name] for name in names], maxiter=generations, popsize=population,
            rng=seed, polish=False, vectorized=True, updating="deferred", tol=1e-4,
            x0=np.clip(start, [BOUNDS[n][0] for n in names], [BOUNDS[n][1] for n in names]),
            callback=lambda *_: shown.update(1) and None)
    return result, time.perf_counter() - began


def tune_scenario(scenario, seed=1, generations=30, population=12, robust=None, criterion=None):
    """Tune one scenario's controller; returns a JSON-ready record (values, RMSE, effort).

    ``robust``: a :class:`~sma_fmu.studies.robust.RobustCriterion`, or None for the RMSE of
    the scenario as it is. ``criterion``: "stroke" or "resistance", or None for the
    scenario's default (:func:`~sma_fmu.studies.criterion.scenario_criterion`). A scenario
    the batch engine does not implement runs on the library path (module docstring).
    """
    names = _tuned_names(scenario)
    objective = _Objective(scenario, names, scenario_criterion(scenario, criterion), robust)
    start = [getattr(scenario.controller, name) for name in names]
    result, seconds = _search(objective, names, start, seed, generations, population,
                              scenario.name)
    return _finish(scenario, names, start, result, objective, robust, seconds, seed)


def tune_jointly(scenarios, seed=1, generations=30, population=12, robust=None, criterion=None):
    """One gain set for all ``scenarios`` (the same gains tuned); a record per scenario.

    **choice**: the score minimised is the worst (largest) of the scenarios' scores, each
    relative to its score at its own given gains (ratios: the criteria's units and scales
    differ; the worst, so that no scenario pays for another's gain). The search starts from
    the first scenario's gains.
    """
    names = _tuned_names(scenarios[0])
    for scenario in scenarios[1:]:
        if _tuned_names(scenario) != names:
            raise StudyError(f"--joint: {scenario.name} tunes {', '.join(_tuned_names(scenario))}"
                             f", {scenarios[0].name} {', '.join(names)}: not one gain set")
    objectives = [_Objective(s, names, scenario_criterion(s, criterion), robust) for s in scenarios]
    starts = [[getattr(s.controller, name) for name in names] for s in scenarios]
    scales = [float(objective(np.array(start))[0]) for objective, start in zip(objectives, starts)]

    def worst(candidates):
        return np.max([objective(candidates) / scale
                       for objective, scale in zip(objectives, scales)], axis=0)

    label = " + ".join(s.name for s in scenarios)
    result, seconds = _search(worst, names, starts[0], seed, generations, population, label)
    records = []
    for scenario, objective, start, scale in zip(scenarios, objectives, starts, scales):
        own = OptimizeResult({**result, "fun": float(objective(result.x)[0])})   # its own score
        record = _finish(scenario, names, start, own, objective, robust, seconds, seed)
        record["joint"] = {"scenarios": [s.name for s in scenarios], "combine": "worst ratio",
                           "given_score": scale, "ratio": own.fun / scale,
                           "worst_ratio": float(result.fun)}
        records.append(record)
    return records


def _finish(scenario, names, start, result, objective, robust, seconds, seed):
    """The record of the search's ``result``: the best gains run again on the library path,
    the given gains' run, the margins, the robust draws and the noise seeds."""
    best = _with_gains(scenario, names, result.x)
    tuned = scenario_metrics(run_library(best).data, best)   # the reported RMSE: scalar path
    given = scenario_metrics(run_library(scenario).data, scenario)
    extra = {"margins": {"given": loop_margins(scenario), "tuned": loop_margins(best)}}
    if scenario.sensor.noise_ohm_rms:
        median, values = noise_seed_rmse(best)
        extra["noise_seeds"] = {"median_ohm": median, "rmse_ohm": values}
    if robust is not None:
        extra["robust"] = _robust_record(scenario, best, names, start, robust)
    record = _record(scenario, names, result, start, tuned, given, objective.evaluations,
                     seconds, seed)
    if is_stroke(scenario.reference):
        extra.update(stroke_fields(objective.criterion, tuned, given, float(result.fun)))
    if objective.reason:
        record["optimiser"]["method"] = ("scipy differential_evolution, on the library path "
                                         f"(not in the batch engine: {objective.reason})")
    return {**record, **extra}


def _record(scenario, names, result, start, tuned, given, evaluations, seconds, seed):
    """The record's fields common to both criteria."""
    return {"scenario": scenario.name, "group": scenario.group,
            "controller": scenario.controller.kind, "inverse": scenario.controller.inverse,
            **{key: getattr(scenario.controller, key) for key in SHAPED_KEYS},
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


def _with_stop_time(scenario, stop_time_s):
    """``scenario`` lasting ``stop_time_s`` [s], checked as in a file (whole steps, at most
    MAX_STEPS, the [analysis] windows inside the run)."""
    try:
        return template(scenario).scenario({"scenario.stop_time_s": float(stop_time_s)})
    except StudyError as error:
        raise StudyError(f"--stop-time {stop_time_s!r}: {error}") from None


def run_tuning(paths, out_dir, seed=1, generations=30, population=12, stop_time_s=None,
               progress=print, robust=None, criterion=None, joint=False):
    """Tune every scenario file in ``paths``; write snippets and reports; return the records.

    ``robust``: a :class:`~sma_fmu.studies.robust.RobustCriterion` or None; ``criterion``:
    "stroke", "resistance" or None (each scenario's default); ``joint``: one gain set for
    all (:func:`tune_jointly`) (see the module docstring)."""
    scenarios = [load_scenario(p) for p in paths]
    for scenario in scenarios:                  # refused before any work starts
        scenario_criterion(scenario, criterion)
    if stop_time_s is not None and not stop_time_s > 0.0:
        raise StudyError(f"--stop-time {stop_time_s!r}: must be > 0 s")
    if stop_time_s is not None:
        scenarios = [_with_stop_time(s, stop_time_s) for s in scenarios]
    if joint:
        progress(f"tuning {len(scenarios)} scenarios jointly "
                 f"({', '.join(_tuned_names(scenarios[0]))}) ...")
        records = tune_jointly(scenarios, seed, generations, population, robust, criterion)
        for record in records:
            progress(f"  {record['scenario']}:")
            print_record(record, robust, progress)
    else:
        records = []
        for index, scenario in enumerate(scenarios, start=1):
            progress(f"[{index}/{len(scenarios)}] tuning {scenario.name} "
                     f"({', '.join(_tuned_names(scenario))}) ...")
            records.append(tune_scenario(scenario, seed, generations, population, robust,
                                         criterion))
            print_record(records[-1], robust, progress)
    with staged_folder(out_dir) as stage:
        for record in records:
            (stage / record["scenario"]).mkdir()
            (stage / record["scenario"] / "controller.toml").write_text(
                controller_snippet(record), encoding="utf-8")
        (stage / "report.json").write_text(json_text(records), encoding="utf-8")
        (stage / "report.md").write_text(ranking_markdown(records), encoding="utf-8")
    return records
