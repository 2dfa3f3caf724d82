"""One Dask task of a sweep: build its runs' scenarios, run them, return one row per run.

The runs go through :func:`~sma_fmu.studies.batch.run_batches`, one batch per step and
duration they share (metrics only, no time series kept; a run that fails there is run
again on the scalar library path, so its row says ``path = library``). A run that cannot
be built or fails is a row with ``status = "failed"`` and the reason in ``error``, never
dropped. With ``fmu_dir`` (``sma-fmu sweep --fmus DIR``) each run goes through the C master
over the FMUs there instead, in the worker's long-lived C master
(:func:`~sma_fmu.systems.c_master.process_master`: one host process, the FMUs loaded once,
reset between runs; metrics only, streamed; ``path = "fmu"``): FMU-path studies at C speed.
"""
from sma_fmu.studies.batch import run_batches
from sma_fmu.studies.overrides import StudyError
from sma_fmu.studies.runs import metrics_record

__all__ = ["STATUSES", "run_row", "run_task"]

STATUSES = ("ok", "failed", "error")   # error: the task itself failed (retried on resume)


def run_row(run, template):
    """The row of ``run`` before it ran: its id, base scenario name, point, draw and
    overrides; status "ok", no error, path, controller or mode yet."""
    row = {"run_id": run.run_id, "scenario": template.name, "point": run.point,
           "draw": run.draw, "status": "ok", "error": None, "path": None,
           "controller": None, "hysteresis_mode": None}
    row.update(run.overrides)
    return row


def _finish(row, scenario, metrics, path, error=None):
    row.update(controller=scenario.controller.kind, hysteresis_mode=scenario.hysteresis_mode,
               path=path)
    if error is not None:
        row.update(status="failed", error=error)
    else:
        row.update(metrics_record(metrics))
    return row


class _Outcome:
    """What :func:`_c_master_runs` gives per run, as a batch outcome does."""

    def __init__(self, metrics, error=None):
        self.metrics, self.path, self.error = metrics, "fmu", error


def _c_master_runs(scenarios, fmu_dir):
    """An outcome per scenario, run in this process's long-lived C master over the FMUs in
    ``fmu_dir`` (one host and its loaded FMUs for all the tasks a worker runs)."""
    from sma_fmu.cosim.metrics import StreamingMetrics
    from sma_fmu.systems.c_master import process_master

    master = process_master(fmu_dir)
    for scenario in scenarios:
        metrics = StreamingMetrics(scenario)
        try:
            master.run(scenario, metrics.update, StreamingMetrics.COLUMNS_READ)
        except (ValueError, RuntimeError) as error:  # a bad FMU or a failed call (FmuError)
            yield _Outcome(None, str(error))
            continue
        yield _Outcome(metrics.result())


def run_task(templates, runs, fmu_dir=None):
    """Rows (dicts) of ``runs`` (:class:`~sma_fmu.studies.spec.StudyRunSpec`), in order;
    through the C master over the FMUs in ``fmu_dir`` when given, else the batch engine."""
    rows, built = {}, []
    for run in runs:
        row = rows[run.run_id] = run_row(run, templates[run.base])
        try:
            scenario = templates[run.base].scenario(run.overrides)
        except StudyError as error:
            row.update(status="failed", error=str(error))
            continue
        built.append((row, scenario))
    scenarios = [s for _, s in built]
    outcomes = run_batches(scenarios) if fmu_dir is None else _c_master_runs(scenarios, fmu_dir)
    for (row, scenario), outcome in zip(built, outcomes):
        _finish(row, scenario, outcome.metrics, outcome.path, outcome.error)
    return [rows[run.run_id] for run in runs]
