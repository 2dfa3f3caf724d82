"""One Dask task of a sweep: build its runs' scenarios, run them, return one row per run.

The runs go through :func:`~sma_fmu.studies.batch.run_batches`, one batch per step and
duration they share (metrics only, no time series kept; a run that fails there is run
again on the scalar library path, so its row says ``path = library``). A run that cannot
be built or fails is a row with ``status = "failed"`` and the reason in ``error``, never
dropped.
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


def run_task(templates, runs):
    """Rows (dicts) of ``runs`` (:class:`~sma_fmu.studies.spec.StudyRunSpec`), in order."""
    rows, built = {}, []
    for run in runs:
        row = rows[run.run_id] = run_row(run, templates[run.base])
        try:
            scenario = templates[run.base].scenario(run.overrides)
        except StudyError as error:
            row.update(status="failed", error=str(error))
            continue
        built.append((row, scenario))
    for (row, scenario), outcome in zip(built, run_batches([s for _, s in built])):
        _finish(row, scenario, outcome.metrics, outcome.path, outcome.error)
    return [rows[run.run_id] for run in runs]
