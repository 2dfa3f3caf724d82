"""The C master in ``sma-fmu bench``: its closed loop against the library's, per scenario.

The loop only (:func:`c_master_times`): each run is what ``sma-fmu run`` does for one
scenario once its master has started, recording included: the loop (the library's
steppers in Python, or the native FMUs in a long-lived C master, ``--master c``, started
and loaded before) streams its rows into a :class:`~sma_fmu.cosim.recording.RunRecorder`
(metrics, the time series in Parquet or CSV, the figure's rows), timed from the start of
the run to the closed file. The two alternate, run i of each next to the other; the ratio
is the median of the per-pair ratios, against :data:`TARGET`. What the user waits for,
whole commands and a sweep, is :mod:`.c_master_commands`'s. The peak memory of a
one-hour run at 1 ms (:func:`hour_run_rss`) is measured in a fresh process.
"""
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.recording import RunRecorder
from sma_fmu.cosim.scenario import PAPER_SET, load_scenario, resolve_scenarios
from sma_fmu.systems.c_master import CMaster

__all__ = ["SCENARIOS", "TARGET", "RSS_TARGET_MB", "c_master_times", "hour_run_rss",
           "c_master_lines"]

SCENARIOS = PAPER_SET + ("setpoints-pwm-pi+ff-adaptive", "setpoints-pwm-continuous-pi+ff-adaptive",
                         # stroke control: the C master maps the stroke reference in C, in the run
                         "flexinol-stroke-load-step-pi+ff-adaptive",
                         "flexinol-stroke-profile-pi+ff-adaptive")
TARGET = 0.25          # C master / library wall time, recording included
RSS_TARGET_MB = 200.0  # peak resident memory of a one-hour run at 1 ms
HOUR_SCENARIO = "setpoints-pwm-pi+ff-adaptive"   # all five FMUs


def _recorded_wall_s(run, scenario, folder, fmt):
    """Wall time [s] of ``run(scenario, sink)`` into a fresh recorder in ``folder``, until
    its files are closed."""
    folder.mkdir(parents=True)
    started = time.perf_counter()
    recorder = RunRecorder(scenario, folder, 1, fmt)
    run(scenario, recorder)
    recorder.close()
    return time.perf_counter() - started


def c_master_times(native_dir, runs, folder, scenarios=SCENARIOS, formats=("parquet", "csv")):
    """{"SCENARIO (FORMAT)": {library_s, c_s (medians), ratio, min, max, runs}} over ``runs``
    alternating runs of each, in one C master (started, its FMUs unpacked and loaded by a
    first run of each scenario)."""
    with CMaster(native_dir) as master:
        return _loop_times(master, runs, Path(folder), scenarios, formats)


def _loop_times(master, runs, folder, scenarios, formats):
    paths = {"library": lambda scenario, sink: run_library(scenario, sink=sink),
             "c": master.run}
    results = {}
    for name in scenarios:
        scenario = load_scenario(resolve_scenarios([name])[0])
        master.run(scenario)
        for fmt in formats:
            walls = {path: [] for path in paths}
            for index in range(runs):
                for path, run in paths.items():
                    target = folder / f"{name}-{fmt}-{path}-{index}"
                    walls[path].append(_recorded_wall_s(run, scenario, target, fmt))
            ratios = [c / library for c, library in zip(walls["c"], walls["library"])]
            results[f"{name} ({fmt})"] = {
                "library_s": round(statistics.median(walls["library"]), 4),
                "c_s": round(statistics.median(walls["c"]), 4),
                "ratio": round(statistics.median(ratios), 3), "min": round(min(ratios), 3),
                "max": round(max(ratios), 3), "runs": runs}
    return results


# the peak is VmHWM (Linux): ru_maxrss keeps, across exec, the peak of the process that
# started this one (the bench itself, some 260 MB after its sweep)
_HOUR_RUN = """
import json, re, resource, sys
from sma_fmu.systems.runner import run_scenarios
run_scenarios([sys.argv[1]], sys.argv[2], "fmu", sys.argv[3], progress=lambda _: None,
              fmt=sys.argv[4], master="c", figures=True)   # the heavier case
try:
    with open("/proc/self/status") as status:
        print(json.dumps(int(re.search(r"VmHWM:\\s*(\\d+) kB", status.read()).group(1))))
except (OSError, AttributeError):
    print(json.dumps(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss))
"""


def hour_run_rss(native_dir, folder, fmt="csv", stop_time_s=3600.0):
    """{"python_mb", "wall_s", "rows", "format"}: peak resident memory [MB] of ``sma-fmu run
    --master c`` (Linux's VmHWM of a fresh Python process) over a one-hour
    (``stop_time_s``) copy of :data:`HOUR_SCENARIO` at 1 ms, recorded as ``fmt``. (The C
    host itself stays near 3 MB: it keeps one frame of rows.)"""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    source = resolve_scenarios([HOUR_SCENARIO])[0].read_text(encoding="utf-8")
    scenario = folder / "one-hour.toml"
    scenario.write_text(source.replace("stop_time_s = 30.0", f"stop_time_s = {stop_time_s!r}"),
                        encoding="utf-8")
    started = time.perf_counter()
    out = folder / "one-hour-results"
    result = subprocess.run([sys.executable, "-c", _HOUR_RUN, str(scenario), str(out),
                             str(native_dir), fmt], capture_output=True, text=True, check=True)
    python_kb = json.loads(result.stdout.strip().splitlines()[-1])
    steps = load_scenario(scenario).steps
    return {"python_mb": round(python_kb / 1024, 1), "wall_s": round(time.perf_counter() - started, 2), "rows": steps + 1, "format": fmt}


def _verdict(value, limit):
    return f"{'meets' if value <= limit else 'MISSES'} target <= {limit:g}"


def c_master_lines(times, hours=None, commands=None, sweep=None):
    """The C-master section of the benchmark table, with its targets: the loop only, then
    (when measured) whole commands and a sweep (:mod:`.c_master_commands`)."""
    from sma_fmu.bench.c_master_commands import command_lines

    runs = next(iter(times.values()))["runs"]
    lines = [f"C master (--master c) / library, the loop only: 30 s at 1 ms, recording "
             f"included (median of {runs} alternating runs, min ... max)",
             f"{'scenario (format)':<58}{'library s':>10}{'C s':>8}{'ratio':>8}"]
    for name, row in times.items():
        lines.append(f"{name:<58}{row['library_s']:>10.3f}{row['c_s']:>8.3f}{row['ratio']:>8.3f}"
                     f"  ({row['min']:.3f} ... {row['max']:.3f})  {_verdict(row['ratio'], TARGET)}")
    for hour in hours or ():
        lines.append(f"one hour at 1 ms ({hour['rows']} rows, {hour['format']}) through the C master: "
                     f"peak RSS {hour['python_mb']:.1f} MB, {hour['wall_s']:.1f} s: {_verdict(hour['python_mb'], RSS_TARGET_MB)} MB")
    if commands or sweep:
        lines += ["", "what the user waits for: whole commands, the run table, a sweep"]
        lines += command_lines(commands or {}, sweep)
    return lines


def run_c_master_bench(out_dir, runs, native_dir=None, progress=print):
    """``sma-fmu bench --only c-master``: build the native FMUs (unless ``native_dir`` holds
    them), time :func:`c_master_times` and :func:`hour_run_rss`; returns the results."""
    from sma_fmu.files.json_output import json_text
    from sma_fmu.files.output_folder import staged_folder

    with staged_folder(out_dir) as stage, tempfile.TemporaryDirectory() as work:
        if native_dir is None:
            from sma_fmu.fmi.packaging.c_family_build import build_native_fmus
            progress("building the native FMUs ...")
            native_dir = Path(build_native_fmus(stage / "native-fmus")["SmaActuator"]).parent
        from sma_fmu.bench import c_master_commands as commands

        progress(f"C master against the library, the loop only ({runs} alternating runs per "
                 f"scenario and format) ...")
        times = c_master_times(native_dir, runs, Path(work) / "runs")
        progress(f"whole `sma-fmu run paper` commands ({runs} alternating, with and without figures) ...")
        whole = commands.run_command_times(native_dir, runs, Path(work) / "commands")
        progress(f"sweep {commands.GAIN_GRID} --fmus on 2 workers, the library on its points ...")
        sweep = commands.sweep_throughput(native_dir, Path(work) / "sweep")
        progress("one hour at 1 ms through the C master ...")
        hour = [hour_run_rss(native_dir, Path(work) / f"hour-{fmt}", fmt) for fmt in ("csv", "parquet")]
        results = {"runs": runs, "c_master": times, "one_hour": hour, "commands": whole,
                   "sweep": sweep,
                   "targets": {"ratio": TARGET, "rss_mb": RSS_TARGET_MB,
                               "command_ratio": commands.COMMAND_TARGET,
                               "wall_ratio": commands.WALL_TARGET,
                               "sweep_ratio": commands.SWEEP_TARGET}}
        (stage / "benchmark.json").write_text(json_text(results), encoding="utf-8")
    return results
