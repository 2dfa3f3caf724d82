"""The C master as a user measures it: whole commands, the run table, a sweep per worker.

- :func:`run_command_times`: ``sma-fmu run paper --fmus DIR --master c`` against ``sma-fmu
  run paper --path library``, each the whole command in a process of its own (start-up,
  imports, unpacking, loading, runs, metrics, reports and figures, until its files are
  closed), alternating, as it is by default (no figures) and with ``--figures``; the output
  files compared (the same names, the same time series); and from each run's
  ``summary.json`` the run table's "wall s" of every scenario, C master over library.
- :func:`sweep_throughput`: the shipped gain grid on two Dask worker processes, each
  running its tasks in its long-lived C master: runs per second per worker process (its
  runs over the time it spent in its tasks, the C master's start-up included; neither the
  worker's imports nor Dask's time between tasks) against the scalar library path's (one over its run table's wall s per run,
  the same points); the whole ``sma-fmu sweep`` command; and whether the sweep's metrics
  equal those of each point run alone in a C master of its own, to the bit.
"""
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

__all__ = ["COMMAND_TARGET", "WALL_TARGET", "SWEEP_TARGET", "GAIN_GRID", "run_command_times",
           "sweep_throughput", "command_lines"]

COMMAND_TARGET = 0.5   # whole `run paper` command, C master / library path
WALL_TARGET = 0.25     # the run table's wall s of a 30 s scenario, C master / library
SWEEP_TARGET = 4.0     # runs per second per worker process, C master sweep / scalar library
GAIN_GRID = "gain-grid.toml"   # the shipped example: 75 runs of 30 s


def _command(arguments, out):
    """Run ``sma-fmu ARGUMENTS --out OUT`` in a process of its own: (wall [s], CPU [s] of
    the process and its children). Python may write its bytecode caches (as an installed
    package has them): PYTHONDONTWRITEBYTECODE would compile every module on every run."""
    environment = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    before = os.times()
    started = time.perf_counter()
    subprocess.run([sys.executable, "-m", "sma_fmu", *arguments, "--out", str(out)],
                   check=True, capture_output=True, env=environment)
    wall = time.perf_counter() - started
    after = os.times()
    return wall, (after.children_user - before.children_user
                  + after.children_system - before.children_system)


def _files(folder):
    return sorted(str(p.relative_to(folder)) for p in Path(folder).rglob("*") if p.is_file())


def _walls(folder):
    """{scenario: the run table's wall s} of a ``run``'s summary.json."""
    rows = json.loads((Path(folder) / "summary.json").read_text(encoding="utf-8"))
    return {row["scenario"]: row["wall_time_s"] for row in rows}


def _same_outputs(c, library):
    """Whether two ``run`` folders hold the same files and the same time series."""
    names = _files(c)
    return names == _files(library) and all(
        (Path(c) / name).read_bytes() == (Path(library) / name).read_bytes()
        for name in names if name.endswith("timeseries.csv"))


def _summary(values):
    return {"median": round(statistics.median(values), 4), "min": round(min(values), 4),
            "max": round(max(values), 4)}


def run_command_times(native_dir, runs, folder, scenarios=("paper",)):
    """{"default, no figures"|"--figures": {c_s, library_s, c_cpu_s, library_cpu_s (medians), ratio
    (median of the per-pair ratios, min, max), same_outputs, walls}} over ``runs``
    alternating whole commands, after one of each to warm the file cache; walls: {scenario:
    ratio of the run table's wall s (median over the runs)}."""
    folder = Path(folder)
    commands = {"c": ["run", *scenarios, "--fmus", str(native_dir), "--master", "c"],
                "library": ["run", *scenarios, "--path", "library"]}
    results = {}
    for label, flags in (("default, no figures", []), ("--figures", ["--figures"])):
        for path, arguments in commands.items():   # warm-up
            _command([*arguments, *flags], folder / f"warm-{path}")
        measured = {path: [] for path in commands}
        same, walls = True, {}
        for index in range(runs):
            outs = {}
            for path, arguments in commands.items():
                outs[path] = folder / f"{'figures' if flags else 'default'}-{path}-{index}"
                measured[path].append(_command([*arguments, *flags], outs[path]))
            same = same and _same_outputs(outs["c"], outs["library"])
            c_walls, library_walls = _walls(outs["c"]), _walls(outs["library"])
            for name in c_walls:
                walls.setdefault(name, []).append(c_walls[name] / library_walls[name])
        ratios = [c[0] / library[0] for c, library in zip(measured["c"], measured["library"])]
        results[label] = {
            "c_s": round(statistics.median(w for w, _ in measured["c"]), 3),
            "library_s": round(statistics.median(w for w, _ in measured["library"]), 3),
            "c_cpu_s": round(statistics.median(c for _, c in measured["c"]), 3),
            "library_cpu_s": round(statistics.median(c for _, c in measured["library"]), 3),
            "ratio": _summary(ratios), "runs": runs, "same_outputs": same,
            "walls": {name: _summary(values) for name, values in walls.items()}}
    return results


def _timed_task(templates, runs, fmu_dir):
    """:func:`~sma_fmu.studies.tasks.run_task` on a worker: (process id, time.time() at its
    start and end, rows, CPU [s] of the worker and of its C master's host); the modules it
    needs are imported before the clock starts (the worker's C master starts, unpacks and
    loads its FMUs inside it)."""
    from sma_fmu.studies.tasks import run_task, worker_master

    master = worker_master(fmu_dir)
    started, cpu, host = time.time(), time.process_time(), master.host_cpu_s()
    rows = run_task(templates, runs, fmu_dir)
    return (os.getpid(), started, time.time(), rows, time.process_time() - cpu,
            master.host_cpu_s() - host)


def _library_walls(spec):
    """The scalar library path on every run of ``spec``: ([its run-table wall s], [CPU [s]
    of the run with its metrics, as a sweep's task computes them])."""
    from sma_fmu.cosim.loop import run_library
    from sma_fmu.cosim.metrics import StreamingMetrics
    from sma_fmu.cosim.recording import RunRecorder
    import tempfile

    walls, cpus = [], []
    with tempfile.TemporaryDirectory() as work:
        for run in spec.runs():
            scenario = spec.templates[run.base].scenario(run.overrides)
            folder = Path(work) / str(run.run_id)
            folder.mkdir()
            recorder = RunRecorder(scenario, folder, 1, "csv")
            result = run_library(scenario, sink=recorder)
            walls.append(result.wall_time_s - recorder.seconds)   # as the runner's table
            recorder.close()
            cpu, metrics = time.process_time(), StreamingMetrics(scenario)
            run_library(scenario, sink=metrics.update)
            metrics.result()
            cpus.append(time.process_time() - cpu)
    return walls, cpus


def _one_at_a_time(spec, native_dir):
    """{run_id: metrics record} of every run of ``spec``, each in a C master of its own."""
    from sma_fmu.cosim.metrics import StreamingMetrics
    from sma_fmu.studies.runs import metrics_record
    from sma_fmu.systems.c_master import CMasterError, run_c_master

    records = {}
    for run in spec.runs():
        scenario = spec.templates[run.base].scenario(run.overrides)
        metrics = StreamingMetrics(scenario)
        try:
            run_c_master(scenario, native_dir, metrics.update)
        except CMasterError:
            continue
        records[run.run_id] = metrics_record(metrics.result())
    return records


def sweep_throughput(native_dir, folder, workers=2, spec_path=None):
    """{"runs", "workers": {pid: runs per second}, "per_worker" (their median),
    "library_per_s", "library_wall_s", "ratio", "c_cpu_ms" and "library_cpu_ms" (CPU per
    run: a worker's and its host's; the library's with its metrics), "sweep_command_s",
    "equal"} of the gain grid (``spec_path``, default the shipped :data:`GAIN_GRID`) over
    ``workers`` Dask worker processes."""
    import pandas as pd

    from sma_fmu.files.package_data import shipped_file
    from sma_fmu.studies.spec import load_spec
    from sma_fmu.studies.sweep import dask_client, task_size

    spec_path = Path(spec_path or shipped_file("examples", GAIN_GRID))
    spec = load_spec(spec_path)
    runs = spec.runs()
    with dask_client(None, workers) as client:
        size = task_size(len(runs), workers, spec.runs_per_task)
        chunks = [runs[i:i + size] for i in range(0, len(runs), size)]
        done = client.gather([client.submit(_timed_task, spec.templates, chunk, str(native_dir),
                                            pure=False) for chunk in chunks])
    busy = {}   # pid -> (seconds in its tasks, runs)
    for pid, start, stop, rows, _, _ in done:
        seconds, count = busy.get(pid, (0.0, 0))
        busy[pid] = (seconds + stop - start, count + len(rows))
    per_worker = {pid: count / seconds for pid, (seconds, count) in busy.items()}
    c_cpu = sum(worker + host for *_, worker, host in done) / len(runs)
    library, library_cpu = _library_walls(spec)
    library_per_s = 1.0 / statistics.mean(library)
    out = Path(folder) / "sweep"
    wall, _ = _command(["sweep", str(spec_path), "--fmus", str(native_dir), "--workers",
                        str(workers), "--quiet"], out)
    table = pd.read_parquet(out / "results.parquet")
    expected = _one_at_a_time(spec, native_dir)
    rows = table.set_index("run_id")
    equal = len(expected) == int((table["status"] == "ok").sum()) and all(
        rows.at[run_id, key] == value or (value is None and pd.isna(rows.at[run_id, key]))
        for run_id, record in expected.items() for key, value in record.items())
    median = statistics.median(per_worker.values())
    return {"runs": len(runs), "workers": {str(k): round(v, 1) for k, v in per_worker.items()},
            "per_worker": round(median, 1), "library_per_s": round(library_per_s, 2),
            "library_wall_s": round(statistics.mean(library), 4),
            "ratio": round(median / library_per_s, 2), "sweep_command_s": round(wall, 2),
            "c_cpu_ms": round(1e3 * c_cpu, 1), "library_cpu_ms": round(1e3 * statistics.mean(library_cpu), 1),
            "equal": equal, "spec": spec_path.name}


def _verdict(value, limit, larger=False):
    met = value >= limit if larger else value <= limit
    return f"{'meets' if met else 'MISSES'} target {'>=' if larger else '<='} {limit:g}"


def command_lines(commands, sweep=None):
    """The bench's lines for :func:`run_command_times` and :func:`sweep_throughput`."""
    lines = []
    for label, row in commands.items():
        ratio = row["ratio"]
        lines.append(f"whole `run paper` command ({label}), C master / library path, median of "
                     f"{row['runs']} alternating: {row['c_s']:.2f} s / {row['library_s']:.2f} s "
                     f"(CPU {row['c_cpu_s']:.2f} / {row['library_cpu_s']:.2f} s) = "
                     f"{ratio['median']:.3f} ({ratio['min']:.3f} ... {ratio['max']:.3f}): "
                     f"{_verdict(ratio['median'], COMMAND_TARGET)}; the same output files: "
                     f"{'yes' if row['same_outputs'] else 'NO'}")
    walls = next(iter(commands.values()))["walls"] if commands else {}
    for name, ratio in walls.items():
        lines.append(f"  run table's wall s, {name}: C master / library {ratio['median']:.3f} "
                     f"({ratio['min']:.3f} ... {ratio['max']:.3f}): "
                     f"{_verdict(ratio['median'], WALL_TARGET)}")
    if sweep is not None:
        lines.append(f"sweep {sweep['spec']} --fmus ({sweep['runs']} runs) on "
                     f"{len(sweep['workers'])} workers: {sweep['per_worker']:.1f} runs/s per "
                     f"worker process ({', '.join(f'{v:.1f}' for v in sweep['workers'].values())}), "
                     f"scalar library {sweep['library_per_s']:.2f} runs/s "
                     f"(wall s per run {sweep['library_wall_s']:.3f}): {sweep['ratio']:.1f} x: "
                     f"{_verdict(sweep['ratio'], SWEEP_TARGET, larger=True)}; CPU per run "
                     f"{sweep['c_cpu_ms']:.1f} ms (worker and its host) against the library's "
                     f"{sweep['library_cpu_ms']:.1f} ms; the whole command "
                     f"{sweep['sweep_command_s']:.1f} s; metrics equal to one-at-a-time C-master "
                     f"runs to the bit: {'yes' if sweep['equal'] else 'NO'}")
    return lines
