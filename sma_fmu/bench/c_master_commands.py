"""The C master as a user measures it: whole commands, the run table, a sweep per worker.

- :func:`run_command_times`: ``sma-fmu run paper --fmus DIR --master c`` against ``sma-fmu
  run paper --path library``, each the whole command in a process of its own (start-up,
  imports, unpacking, loading, runs, metrics, reports and figures, until its files are
  closed), alternating, as it is by default (no figures) and with ``--figures``; the output
  files compared (the same names, the same time series); and from each run's
  ``summary.json`` the run table's "wall s" of every scenario, C master over library.
- :func:`sweep_throughput`: the shipped gain grid on two Dask worker processes, each
  running its tasks in its long-lived C master, against the scalar library path on the
  same points in the same worker processes, phase by phase (C master, library, C master,
  ...): runs per second per worker process (its runs over the time it spent in its tasks,
  the C master's start-up included; neither the worker's imports nor Dask's time between
  tasks) against the library's (one over its run table's wall s per run, the same points,
  as many processes at once, at the same time); the CPU per run of both; the whole ``sma-fmu
  sweep`` command; and whether the sweep's metrics equal those of each point run alone in a
  C master of its own, to the bit. Both paths run in the same kind of process, two at once:
  where the kernel shares the CPU between sessions first (Linux's autogroup), a library
  run alone would have the session's share to itself while each C-master worker shares
  it with the other, and under load the ratio would fall towards half.
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
    """:func:`~sma_fmu.studies.tasks.run_task` on a worker: (process id, seconds in it, rows,
    CPU [s] of the worker and of its C master's host); the modules it needs are imported
    before the clock starts (the worker's C master starts, unpacks and loads its FMUs inside
    it when the task is the first of its phase)."""
    from sma_fmu.studies.tasks import run_task, worker_master

    master = worker_master(fmu_dir)
    started, cpu, host = time.perf_counter(), time.process_time(), master.host_cpu_s()
    rows = run_task(templates, runs, fmu_dir)
    return (os.getpid(), time.perf_counter() - started, len(rows), time.process_time() - cpu,
            master.host_cpu_s() - host)


def _library_task(templates, runs):
    """The scalar library path on ``runs`` on a worker, each with the streamed metrics a
    sweep's task computes: (process id, seconds in it, [each run's run-table wall s: the
    run less the time in its sink, as the runner's table], CPU [s] of the task)."""
    from sma_fmu.cosim.loop import run_library
    from sma_fmu.cosim.metrics import StreamingMetrics

    started, cpu, walls = time.perf_counter(), time.process_time(), []
    for run in runs:
        scenario = templates[run.base].scenario(run.overrides)
        metrics, spent = StreamingMetrics(scenario), [0.0]

        def sink(block, update=metrics.update, spent=spent):
            begun = time.perf_counter()
            update(block)
            spent[0] += time.perf_counter() - begun

        result = run_library(scenario, sink=sink)
        metrics.result()
        walls.append(result.wall_time_s - spent[0])
    return os.getpid(), time.perf_counter() - started, walls, time.process_time() - cpu


def _per_worker(done, runs_of):
    """{pid: runs per second} of a phase's finished tasks ``done`` (``runs_of(task)``: its
    (runs, seconds))."""
    busy = {}
    for task in done:
        count, seconds = runs_of(task)
        so_far = busy.get(task[0], (0, 0.0))
        busy[task[0]] = (so_far[0] + count, so_far[1] + seconds)
    return {pid: count / seconds for pid, (count, seconds) in busy.items()}


def _phases(client, spec, chunks, native_dir, rounds):
    """C-master and library phases on the same workers, C first and last, alternating: each
    phase runs every chunk (the sweep's tasks) on all the workers at once; before each C
    phase the workers are restarted, so each C phase pays what a new sweep's workers pay
    (its C master's start-up: the host started, the FMUs' model descriptions read, the FMUs
    unpacked and loaded). ([C phases' {pid: runs/s}], [library phases' ({pid: runs/s by
    the run table's wall s}, {pid: runs/s in its tasks, metrics included})], CPU [s] per
    run of the C master (worker and host) and of the library (with its metrics))."""
    c_phases, library_phases, c_cpu, library_cpu = [], [], [], []
    for index in range(2 * rounds + 1):
        if index % 2 == 0:
            if index:
                client.restart()
            done = client.gather([client.submit(_timed_task, spec.templates, chunk, native_dir,
                                                pure=False) for chunk in chunks])
            c_phases.append(_per_worker(done, lambda task: (task[2], task[1])))
            c_cpu += [(task[3] + task[4]) / task[2] for task in done for _ in range(task[2])]
            continue
        done = client.gather([client.submit(_library_task, spec.templates, chunk, pure=False)
                              for chunk in chunks])
        library_phases.append((_per_worker(done, lambda task: (len(task[2]), sum(task[2]))),
                               _per_worker(done, lambda task: (len(task[2]), task[1]))))
        library_cpu += [task[3] / len(task[2]) for task in done for _ in task[2]]
    return c_phases, library_phases, statistics.mean(c_cpu), statistics.mean(library_cpu)


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


def sweep_throughput(native_dir, folder, workers=2, spec_path=None, rounds=3):
    """{"runs", "workers": [C-master runs per second of each phase's fastest worker, its
    next, ... (medians over the phases)],
    "per_worker" (median over the C phases of their workers' median), "library_per_s" (the
    same of the library phases, one over the run table's wall s per run), "library_wall_s",
    "library_task_per_s" (the library's runs per second in its tasks, metrics included),
    "ratio" {"median", "min", "max"} (over the library phases: the mean of the C phases
    before and after it over it), "ratio_with_metrics", "c_cpu_ms" and "library_cpu_ms" (CPU
    per run: a worker's and its host's; the library's with its metrics), "cpu_ratio",
    "sweep_command_s", "equal", "load"} of the gain grid (``spec_path``, default the
    shipped :data:`GAIN_GRID`) on ``workers`` Dask worker processes: ``rounds`` library
    phases between ``rounds + 1`` C-master phases, on the same workers (:func:`_phases`),
    so both paths are measured alike: as many processes at once, the same metrics, the same
    clock, at the same time."""
    from sma_fmu.files.package_data import shipped_file
    from sma_fmu.studies.spec import load_spec
    from sma_fmu.studies.sweep import dask_client, task_size

    spec_path = Path(spec_path or shipped_file("examples", GAIN_GRID))
    spec = load_spec(spec_path)
    runs = spec.runs()
    load = os.getloadavg()[0]
    with dask_client(None, workers) as client:
        size = task_size(len(runs), workers, spec.runs_per_task)
        chunks = [runs[i:i + size] for i in range(0, len(runs), size)]
        c, library, c_cpu, library_cpu = _phases(client, spec, chunks, str(native_dir), rounds)
    c_rates = [statistics.median(phase.values()) for phase in c]
    walls = [statistics.median(table.values()) for table, _ in library]
    tasks = [statistics.median(table.values()) for _, table in library]
    around = [(c_rates[i] + c_rates[i + 1]) / 2 for i in range(rounds)]
    slots = [sorted(phase.values(), reverse=True) for phase in c]   # fastest worker first
    out = Path(folder) / "sweep"
    wall, _ = _command(["sweep", str(spec_path), "--fmus", str(native_dir), "--workers",
                        str(workers), "--quiet"], out)
    median = statistics.median(walls)
    return {"runs": len(runs), "rounds": rounds,
            "workers": [round(statistics.median(rates), 1) for rates in zip(*slots)],
            "per_worker": round(statistics.median(c_rates), 1),
            "library_per_s": round(median, 2), "library_wall_s": round(1.0 / median, 4),
            "library_task_per_s": round(statistics.median(tasks), 2),
            "ratio": _summary([a / b for a, b in zip(around, walls)]),
            "ratio_with_metrics": _summary([a / b for a, b in zip(around, tasks)]),
            "c_cpu_ms": round(1e3 * c_cpu, 1), "library_cpu_ms": round(1e3 * library_cpu, 1),
            "cpu_ratio": round(library_cpu / c_cpu, 2), "sweep_command_s": round(wall, 2),
            "equal": _sweep_equals(out, spec, native_dir), "spec": spec_path.name,
            "load": [round(load, 2), round(os.getloadavg()[0], 2)]}


def _sweep_equals(out, spec, native_dir):
    """Whether the sweep in ``out`` holds, for every run, the metrics of its point run alone
    in a C master of its own, to the bit."""
    import pandas as pd

    table = pd.read_parquet(Path(out) / "results.parquet")
    expected = _one_at_a_time(spec, native_dir)
    rows = table.set_index("run_id")
    return len(expected) == int((table["status"] == "ok").sum()) and all(
        rows.at[run_id, key] == value or (value is None and pd.isna(rows.at[run_id, key]))
        for run_id, record in expected.items() for key, value in record.items())


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
        ratio, metered = sweep["ratio"], sweep["ratio_with_metrics"]
        lines.append(f"sweep {sweep['spec']} --fmus ({sweep['runs']} runs) on "
                     f"{len(sweep['workers'])} workers, {sweep['rounds']} library phases between "
                     f"C-master phases on the same workers (load average {sweep['load'][0]:.1f}"
                     f"-{sweep['load'][1]:.1f}): {sweep['per_worker']:.1f} runs/s per worker "
                     f"process ({', '.join(f'{v:.1f}' for v in sweep['workers'])}), "
                     f"scalar library {sweep['library_per_s']:.2f} runs/s per worker process "
                     f"(run table's wall s per run {sweep['library_wall_s']:.3f}): "
                     f"{ratio['median']:.1f} x ({ratio['min']:.1f} ... {ratio['max']:.1f}): "
                     f"{_verdict(ratio['median'], SWEEP_TARGET, larger=True)}")
        lines.append(f"  the library's runs/s in its tasks, metrics included (as the C master's): "
                     f"{sweep['library_task_per_s']:.2f}: {metered['median']:.1f} x "
                     f"({metered['min']:.1f} ... {metered['max']:.1f}); CPU per run "
                     f"{sweep['c_cpu_ms']:.1f} ms (worker and its host) against the library's "
                     f"{sweep['library_cpu_ms']:.1f} ms (with its metrics): {sweep['cpu_ratio']:.1f} x; "
                     f"the whole command {sweep['sweep_command_s']:.1f} s; metrics equal to "
                     f"one-at-a-time C-master runs to the bit: {'yes' if sweep['equal'] else 'NO'}")
    return lines
