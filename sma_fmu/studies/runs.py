"""The study API: run scenarios (with overrides) on any path; time series as DataFrames.

::

    from sma_fmu.studies import run, run_many

    result = run("load-step-pi+ff-adaptive", {"controller.Kp_W_per_ohm": 0.5}, path="batch")
    result.timeseries            # pandas DataFrame, columns t_s, R_ref_ohm, R_ohm, ...
    result.metrics               # the record of sma_fmu.cosim.metrics.scenario_metrics
    result.record()              # the same, flat: one row of a results table

Paths: ``"library"`` (the runtime steppers, :func:`sma_fmu.cosim.loop.run_library`),
``"fmu"`` (the built FMUs under fmpy, :func:`sma_fmu.cosim.master.run_fmus`; with
``master="c"`` in one C master for all the runs, :class:`sma_fmu.systems.c_master.CMaster`)
and ``"batch"`` (:func:`sma_fmu.studies.batch.run_batches`; many runs in lock-step).
"""
from dataclasses import dataclass

import pandas as pd

from sma_fmu.cosim.loop import COLUMN_NAMES, COLUMNS, run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.scenario import Scenario
from sma_fmu.fmi.packaging.fmu_names import DEFAULT_FMU_DIR
from sma_fmu.studies.batch import run_batches, unsupported_reason
from sma_fmu.studies.overrides import StudyError, template

__all__ = ["PATHS", "StudyRun", "scenario", "run", "run_many", "timeseries_frame",
           "metrics_record"]

PATHS = ("library", "fmu", "batch")


def timeseries_frame(data):
    """A loop's structured time-series array as a DataFrame; columns named as in the CSV."""
    return pd.DataFrame({column: data[name] for (name, _), column in zip(COLUMNS, COLUMN_NAMES)})


def metrics_record(metrics):
    """A :func:`scenario_metrics` record flattened to one row: overall metrics, the saturated,
    clamped and unreachable fractions, and per load segment ``segment{i}_load_kg`` and
    ``segment{i}_rmse_ohm``."""
    row = {f"{name}": metrics["overall"][name]
           for name in ("rmse_ohm", "max_abs_ohm", "iae_ohm_s", "samples")}
    for name in ("saturated_fraction", "clamped_fraction", "unreachable_fraction"):
        row[name] = metrics.get(name)
    for index, segment in enumerate(metrics["segments"]):
        row[f"segment{index}_load_kg"] = segment["load_kg"]
        row[f"segment{index}_rmse_ohm"] = segment["rmse_ohm"]
    return row


@dataclass
class StudyRun:
    """One run: its scenario, time series (DataFrame), metrics record, path and wall time [s]."""

    scenario: Scenario
    timeseries: pd.DataFrame
    metrics: dict
    path: str
    wall_time_s: float

    def record(self):
        """Scenario name, controller, mode and the flat metrics (:func:`metrics_record`)."""
        return {"scenario": self.scenario.name, "controller": self.scenario.controller.kind,
                "hysteresis_mode": self.scenario.hysteresis_mode, "path": self.path,
                **metrics_record(self.metrics)}


def scenario(base, overrides=None):
    """A scenario (file path, shipped name or Scenario) with ``overrides`` applied.

    ``overrides`` maps ``"section.key"`` or ``"wire.NAME"`` to a value; see
    :mod:`sma_fmu.studies.overrides`.
    """
    if isinstance(base, Scenario) and not overrides:
        return base
    return template(base).scenario(overrides)


def run(base, overrides=None, path="library", fmu_dir=DEFAULT_FMU_DIR, master="fmpy"):
    """Run one scenario (see :func:`scenario`) on ``path``; returns a :class:`StudyRun`."""
    return run_many([scenario(base, overrides)], path, fmu_dir, master)[0]


def run_many(scenarios, path="batch", fmu_dir=DEFAULT_FMU_DIR, master="fmpy"):
    """Run Scenario objects on ``path``; returns a :class:`StudyRun` per scenario, in order.

    On the batch path, scenarios that share the step and duration run as one batch; a
    scenario with an option the batch engine lacks raises :class:`StudyError`. A run
    that fails raises ``ValueError`` with the scalar path's message. ``master`` (the fmu
    path): ``"fmpy"``, or ``"c"``: every run in one C master (one host process, the FMUs
    loaded once; native FMI 2.0 FMUs, ``sma-fmu build --native``).
    """
    if path not in PATHS:
        raise StudyError(f"path must be one of {', '.join(PATHS)}, got {path!r}")
    if master not in ("fmpy", "c") or (master == "c" and path != "fmu"):
        raise StudyError(f"master must be 'fmpy', or 'c' with path='fmu'; got master={master!r} "
                         f"with path={path!r}")
    scenarios = list(scenarios)
    if master == "c":
        from sma_fmu.systems.c_master import CMaster
        with CMaster(fmu_dir) as c_master:
            return [_study_run(s, c_master.run(s), path) for s in scenarios]
    if path != "batch":
        return [_single(s, path, fmu_dir) for s in scenarios]
    for item in scenarios:
        reason = unsupported_reason(item)
        if reason:
            raise StudyError(f"{reason}; use path='library'")
    outcomes = run_batches(scenarios, "timeseries")
    for outcome in outcomes:
        if outcome.error is not None:
            raise ValueError(f"scenario {outcome.scenario.name}: {outcome.error}")
    return [StudyRun(outcome.scenario, timeseries_frame(outcome.data), outcome.metrics,
                     outcome.path, outcome.wall_time_s) for outcome in outcomes]


def _single(item, path, fmu_dir):
    if path == "fmu":
        from sma_fmu.cosim.master import run_fmus
        result = run_fmus(item, fmu_dir)
    else:
        result = run_library(item)
    return _study_run(item, result, path)


def _study_run(item, result, path):
    return StudyRun(item, timeseries_frame(result.data), scenario_metrics(result.data, item),
                    path, result.wall_time_s)
