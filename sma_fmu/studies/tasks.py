"""One Dask task of a sweep: build its runs' scenarios, run them, return one row per run.

The runs go through :func:`~sma_fmu.studies.batch.run_batches`, one batch per step and
duration they share (metrics only, no time series kept; a run that fails there is run
again on the scalar library path, so its row says ``path = library``). A run that cannot
be built or fails is a row with ``status = "failed"`` and the reason in ``error``, never
dropped. With ``fmu_dir`` (``sma-fmu sweep --fmus DIR``) each run goes through the C master
over the FMUs there instead, in the worker's long-lived C master
(:func:`worker_master`: one host process, the FMUs loaded once,
reset between runs, each run given to the host before the last one's rows are read;
metrics only, streamed; ``path = "fmu"``): FMU-path studies at C speed.
"""
import atexit
import os
import sys
import threading
from pathlib import Path

from sma_fmu.studies.batch import run_batches
from sma_fmu.studies.overrides import StudyError
from sma_fmu.studies.runs import metrics_record

__all__ = ["STATUSES", "run_row", "run_task", "worker_master", "close_worker_masters"]

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


_MASTERS = {}   # (FMU folder, thread) -> CMaster: each worker's long-lived C master
_MASTERS_LOCK = threading.Lock()
_EXIT_REGISTERED = set()   # the processes that registered close_worker_masters at exit


def worker_master(fmu_dir):
    """This process's (and thread's) :class:`~sma_fmu.systems.c_master.CMaster` over
    ``fmu_dir``, made at the first call and kept for the next ones (a study's points on a
    Dask worker share it) until the process exits (:func:`close_worker_masters`)."""
    from sma_fmu.systems.c_master import CMaster

    key = (str(Path(fmu_dir).resolve()), threading.get_ident())
    with _MASTERS_LOCK:
        master = _MASTERS.get(key)
        if master is None:
            master = _MASTERS[key] = CMaster(fmu_dir)
            _close_at_exit()
        return master


def close_worker_masters():
    """Close the masters :func:`worker_master` made (their hosts end)."""
    with _MASTERS_LOCK:
        masters = list(_MASTERS.values())
        _MASTERS.clear()
    for master in masters:
        master.close()


def _close_at_exit():
    """At this process's exit: atexit, and multiprocessing's finalizers (its children, as
    Dask's worker processes, end with os._exit and skip atexit)."""
    if os.getpid() in _EXIT_REGISTERED:
        return
    _EXIT_REGISTERED.add(os.getpid())
    atexit.register(close_worker_masters)
    util = sys.modules.get("multiprocessing.util")
    if util is not None:
        util.Finalize(None, close_worker_masters, exitpriority=1)


def _c_master_runs(scenarios, fmu_dir):
    """An outcome per scenario, run in this process's long-lived C master over the FMUs in
    ``fmu_dir`` (one host and its loaded FMUs for all the tasks a worker runs)."""
    from sma_fmu.cosim.metrics import StreamingMetrics

    metrics = [StreamingMetrics(scenario) for scenario in scenarios]
    results = worker_master(fmu_dir).run_many(
        [(scenario, sums.update) for scenario, sums in zip(scenarios, metrics)],
        StreamingMetrics.COLUMNS_READ)
    for sums, result in zip(metrics, results):
        if isinstance(result, Exception):  # a bad FMU or a failed call (FmuError)
            yield _Outcome(None, str(result))
        else:
            yield _Outcome(sums.result())


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
