"""``sma-fmu sweep``: run a study spec on Dask distributed, streaming results to disk.

The runs are split into tasks (:func:`~sma_fmu.studies.tasks.run_task`) and sent to a
Dask cluster: a ``LocalCluster`` of worker processes by default, or an existing cluster
with ``scheduler`` (its workers need sma-fmu installed). Each finished task's rows are
written at once to ``OUT/runs/part-*.parquet`` (through a temporary file and a rename),
so memory holds no more than the tasks in flight, and an interrupted sweep keeps what it
finished. Running the same spec into the same folder again resumes: runs already in a
part (succeeded or failed) are not run again; runs of a task that itself failed (status
"error", e.g. a worker died) are. ``OUT/study.json`` records the spec's fingerprint; a
different spec into the same folder is refused. At the end, :mod:`~sma_fmu.studies.results`
writes the table, the summary and the figures. With ``fmu_dir`` (``--fmus DIR``) the runs
go through the C master over those FMUs (:func:`~sma_fmu.studies.tasks.run_task`); the
FMUs are checked against every base scenario before anything starts, and a folder holds
the runs of one path only (``study.json`` says which).
"""
import contextlib
import io
import json
import logging
import math
import os
import signal
import tempfile
from pathlib import Path

import pandas as pd

from sma_fmu.console.interrupts import children_spared, deferred
from sma_fmu.files.json_output import json_text
from sma_fmu.fmi.driving.unpacked import remove_stale
from sma_fmu.files.output_folder import check_folder, write_file
from sma_fmu.studies.overrides import StudyError
from sma_fmu.studies.results import PARTS, read_parts, write_results
from sma_fmu.studies.spec import load_spec
from sma_fmu.studies.tasks import run_row, run_task

__all__ = ["run_sweep", "finished_runs", "dask_client", "task_size"]

MOST_RUNS_PER_TASK = 1000


@contextlib.contextmanager
def dask_client(scheduler=None, workers=None):
    """A ``dask.distributed.Client``: of ``scheduler`` (an address), or of a new LocalCluster
    with ``workers`` single-threaded worker processes (default: one per core)."""
    import dask
    from dask.distributed import Client, LocalCluster
    if scheduler is not None:
        try:
            client = Client(scheduler, timeout="20s")
        except (OSError, TimeoutError) as error:
            raise StudyError(f"--scheduler {scheduler}: cannot connect ({error})") from None
        with client:
            yield client
        return
    count = workers or os.cpu_count() or 1
    # A terminal's Ctrl-C reaches this process alone (children_spared), never a cluster half
    # started or half closed (deferred): cut there, the workers printed their
    # KeyboardInterrupts and Dask, at exit, "AssertionError: Status.init". After a Ctrl-C the
    # workers are ended at once (they would finish their task first, seconds).
    # the workers' scratch space in a folder of the sweep's own, removed after it (Dask's
    # default, TMPDIR/dask-scratch-space, stays, with locks of workers a Ctrl-C ended)
    cluster = client = None
    with tempfile.TemporaryDirectory(prefix="dask-sweep-", ignore_cleanup_errors=True) as scratch, \
            dask.config.set({"temporary-directory": scratch}), contextlib.ExitStack() as quiet:
        try:
            with deferred(), children_spared():
                # no dashboard; the scheduler's HTTP server (always started) on a free port:
                # on its default, 8787, a second sweep at the same time printed Dask's
                # "Port 8787 is already in use" warning
                cluster = LocalCluster(n_workers=count, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=logging.ERROR,
                                       scheduler_kwargs={"dashboard_address": ":0"})
                client = Client(cluster)
            yield client
        except KeyboardInterrupt:
            quiet.enter_context(_logs_silenced())   # Dask's lost connections to them
            _end_workers(cluster)
            quiet.callback(remove_stale)   # the FMU folders they unpacked (--fmus), once closed
            raise
        finally:
            with deferred():
                for part in (client, cluster):
                    if part is not None:
                        part.close()


@contextlib.contextmanager
def _logs_silenced():
    """No logger prints in the body (``logging.disable``; what was disabled before, after)."""
    before = logging.root.manager.disable
    logging.disable(logging.CRITICAL)
    try:
        yield
    finally:
        logging.disable(before)


def _end_workers(cluster):
    """End the worker processes of the LocalCluster ``cluster`` at once (SIGTERM: their
    exit handlers do not run; what they leave, :func:`remove_stale` removes)."""
    for nanny in getattr(cluster, "workers", {}).values():
        pid = getattr(nanny, "pid", None)   # the worker process's (its nanny runs in here)
        if pid:
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGTERM)


def task_size(remaining, workers, requested=None):
    """Runs per task: ``requested``, or an even split over twice the workers, at most 1000."""
    if requested:
        return requested
    return max(1, min(MOST_RUNS_PER_TASK, math.ceil(remaining / (2 * max(workers, 1)))))


def finished_runs(out):
    """{run_id: status} of the runs already written to ``out``/runs (an error is not final)."""
    table = read_parts(out, ["run_id", "status"])
    table = table[table["status"] != "error"]
    return dict(zip(table["run_id"].tolist(), table["status"].tolist()))


def _check_folder(out, spec, path="batch"):
    """Check that ``out`` is new or holds a sweep of the same spec and path; the text of the
    ``study.json`` to write there (None: it is there), written once the cluster is up, so a
    sweep that cannot start (no scheduler at ``--scheduler``) leaves no folder."""
    out = Path(out)
    check_folder(out)
    marker = out / "study.json"
    fingerprint = spec.fingerprint()
    if marker.is_file():
        recorded = json.loads(marker.read_text(encoding="utf-8"))
        if recorded.get("fingerprint") != fingerprint:
            raise StudyError(f"--out {out}: holds the results of another study spec "
                             f"(study.json); give another --out, or remove that folder")
        if recorded.get("path", "batch") != path:
            raise StudyError(f"--out {out}: holds runs of the {recorded.get('path', 'batch')} path, "
                             f"not {path} (--fmus); give another --out, or remove that folder")
        return None
    return json_text({"spec": str(spec.path), "fingerprint": fingerprint,
                      "runs": len(spec.runs()), "path": path})


def _check_fmus(spec, fmu_dir):
    """Every base scenario's loop in ``fmu_dir``: a missing FMU or one whose variables do
    not match is refused before the sweep starts (the message names it)."""
    from sma_fmu.fmi.loop.system import check_variables
    from sma_fmu.systems.closed_loop import closed_loop

    for template in spec.templates:
        check_variables(closed_loop(template.scenario({}), fmu_dir))


def _write_part(out, rows):
    buffer = io.BytesIO()
    pd.DataFrame(rows).to_parquet(buffer, index=False)
    first = min(row["run_id"] for row in rows)
    status = "error" if all(row["status"] == "error" for row in rows) else "part"
    name = f"part-{first:08d}-{len(rows):05d}{'-error' if status == 'error' else ''}.parquet"
    write_file(Path(out) / PARTS / name, buffer.getvalue(), final=False)   # kept for a resume


def _error_rows(spec, runs, reason):
    """Rows of ``runs`` whose task failed: status "error" (retried on resume), ``reason``."""
    return [{**run_row(run, spec.templates[run.base]), "status": "error", "error": reason}
            for run in runs]


def run_sweep(spec_path, out, scheduler=None, workers=None, progress=True, fmu_dir=None):
    """Run the study spec at ``spec_path`` into folder ``out``; returns the summary dict.
    ``fmu_dir``: run through the C master over the FMUs there (else the batch engine)."""
    from dask.distributed import as_completed

    from sma_fmu.console import progress as console_progress

    spec = load_spec(spec_path)
    runs = spec.runs()
    if fmu_dir is not None:
        fmu_dir = str(Path(fmu_dir).resolve())   # the workers' working folder may differ
        _check_fmus(spec, fmu_dir)
    marker = _check_folder(out, spec, "batch" if fmu_dir is None else "fmu")
    done = finished_runs(out)
    todo = [run for run in runs if run.run_id not in done]
    if todo:
        with dask_client(scheduler, workers) as client:
            if marker is not None:
                write_file(Path(out) / "study.json", marker, final=False)
            count = len(client.scheduler_info().get("workers", {})) or 1
            size = task_size(len(todo), count, spec.runs_per_task)
            chunks = [todo[i:i + size] for i in range(0, len(todo), size)]
            futures = {client.submit(run_task, spec.templates, chunk, fmu_dir, pure=False): chunk
                       for chunk in chunks}
            with console_progress.bar(len(runs), "sweep", unit="run", disable=not progress,
                                      initial=len(runs) - len(todo)) as bar:
                for future in as_completed(futures):
                    chunk = futures.pop(future)
                    try:
                        rows = future.result()
                    except Exception as error:  # noqa: BLE001 - recorded, retried on resume
                        rows = _error_rows(spec, chunk, f"task failed: {type(error).__name__}: "
                                                        f"{error}")
                    _write_part(out, rows)
                    bar.update(len(chunk))
                    future.release()
    return write_results(spec, out)
