"""Benchmarks: how fast the FMUs, the co-simulation and the fits run (medians of several runs).

``sma-fmu bench``: prints a table against the targets and
writes ``benchmark.json``. Speed is measured here and never asserted in tests. The same
run measures two baselines, so the numbers compare across machines: a trivial pythonfmu
FMU (y = u) stepped the same way, and a plain Python loop.
"""
import math
import platform
import statistics
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from sma_fmu.bench.c_hosts import C_HOST_STEPS, c_host_step_costs, floor_costs
from sma_fmu.cosim.loop import run_library
from sma_fmu.fmi.packaging.build import build_fmus
from sma_fmu.fmi.driving.instance import FmuInstance
from sma_fmu.cosim.master import run_fmus
from sma_fmu.files.json_output import json_text
from sma_fmu.files.output_folder import staged_folder
from sma_fmu.files.package_data import shipped_file
from sma_fmu.cosim.scenario import CONTROLLERS, load_scenario, resolve_scenarios

__all__ = ["TARGETS", "run_benchmarks", "run_batch_benchmark", "format_table", "main"]

STEP = 1e-3
TARGETS = {  # the project's speed targets, on a 2-core machine
    "closed_loop_fmu_s": 0.5,                  # 30 s load-step through both FMUs + PI
    "feedforward_step_us": 15.0,               # SmaFeedforward set + doStep + get
    "library_real_time_factor": 150.0,         # per scenario
    "identification_s": 2.0,                   # the 4-load constant-load fit
    "c_host_vs_fmpy": 2.0,                     # SmaActuator step in a C host / fmpy master
}
RATIO_TARGETS = {  # (target, stretch or None); an earlier target for the C host was 1.5
    "FMU closed loop / library path": (3.0, 2.0),
    "SmaActuator in the C host / library plant step": (2.0, None),
}
_TRIVIAL_SLAVE = '''
from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Real


class Trivial(Fmi2Slave):
    """Benchmark baseline: y = u."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.u = 0.0
        self.y = 0.0
        self.register_variable(Real("u", causality=Fmi2Causality.input))
        self.register_variable(Real("y", causality=Fmi2Causality.output,
                                    variability=Fmi2Variability.continuous,
                                    initial=Fmi2Initial.exact))

    def do_step(self, current_time, step_size):
        self.y = self.u
        return True
'''


def _median(samples):
    return statistics.median(samples)


def _fmu_step_us(path, inputs, outputs, values, runs, steps, with_io, fmpy_api=False):
    """Median cost [us] of one step: doStep alone, or set inputs + doStep + get outputs."""
    costs = []
    for run in range(runs):
        with FmuInstance(path, f"bench-{run}") as fmu:
            put, take = fmu.port(inputs), fmu.port(outputs)
            if fmpy_api:  # fmpy's own FMU2Slave methods, as a plain fmpy user would call them
                raw = fmu._fmu
                refs_in, refs_out = list(put.references), list(take.references)
                put_values = lambda k: raw.setReal(refs_in, values(k))
                take_values = lambda: raw.getReal(refs_out)
                do_step = raw.doStep
            else:
                put_values = lambda k: put.set(values(k))
                take_values = take.get
                do_step = fmu.step
            t = 0.0
            start = time.perf_counter()
            for k in range(steps):
                if with_io:
                    put_values(k)
                do_step(t, STEP)
                if with_io:
                    take_values()
                t += STEP
            costs.append((time.perf_counter() - start) / steps * 1e6)
    return round(_median(costs), 2)


FMU_CASES = {
    "SmaActuator": (("P_in", "load"), ("R", "T"),
                    lambda k: (1.9 + 0.9 * math.sin(math.pi * k * STEP), 0.05)),
    "SmaFeedforward": (("R_ref", "load"), ("P_ff", "T_ref"),
                       lambda k: (41.85 + 6.05 * math.cos(math.pi * k * STEP), 0.05)),
    "Trivial (baseline)": (("u",), ("y",), lambda k: (float(k),)),
}


def fmu_step_costs(paths, runs, steps=3000):
    """{FMU: {doStep, set+doStep+get, same via fmpy FMU2Slave API}} in us (medians)."""
    results = {}
    for name, (inputs, outputs, values) in FMU_CASES.items():
        args = (paths[name], inputs, outputs, values, runs, steps)
        results[name] = {"doStep_us": _fmu_step_us(*args, with_io=False),
                         "set_doStep_get_us": _fmu_step_us(*args, with_io=True),
                         "fmpy_api_set_doStep_get_us": _fmu_step_us(*args, with_io=True, fmpy_api=True)}
    return results


def closed_loop_times(fmu_dir, runs):
    """load-step, 30 s at 1 ms, per controller and path: median wall [s], real-time factor and
    every run's wall [s] (``walls_s``; the two paths alternate, so run i of each compare)."""
    results = {}
    for controller in CONTROLLERS:
        scenario = load_scenario(shipped_file("scenarios", f"load-step-{controller}.toml"))
        runners = {"fmu": lambda: run_fmus(scenario, fmu_dir), "library": lambda: run_library(scenario)}
        walls = {path: [] for path in runners}
        for _ in range(runs):
            for path, run in runners.items():
                walls[path].append(run().wall_time_s)
        for path, samples in walls.items():
            wall = round(_median(samples), 4)  # the factor from the wall as printed
            results[f"{controller} ({path})"] = {
                "wall_s": round(wall, 4), "min_s": round(min(samples), 4),
                "max_s": round(max(samples), 4), "real_time_factor": round(scenario.stop_time_s / wall, 1),
                "walls_s": [round(w, 5) for w in samples]}
    return results


def ratio_table(loops, floor):
    """{ratio name: {median, min, max, runs}}: each FMU closed loop over the library run next to
    it, and the C-host / fmpy-master / native-FMU ratios of :func:`floor_costs`."""
    samples = {}
    for controller in CONTROLLERS:
        fmu, library = loops[f"{controller} (fmu)"], loops[f"{controller} (library)"]
        samples[f"FMU closed loop / library path, {controller}"] = [
            a / b for a, b in zip(fmu["walls_s"], library["walls_s"])]
    samples.update(floor["ratios"])
    return {name: {"median": round(_median(values), 3), "min": round(min(values), 3),
                   "max": round(max(values), 3), "runs": len(values)}
            for name, values in samples.items()}


def _library_run(path):
    return run_library(load_scenario(path)).wall_time_s


def library_throughput(workers=2):
    """Runs per second of the library path over every shipped scenario, 1 and ``workers`` processes."""
    paths = [str(p) for p in resolve_scenarios([], everything=True)]
    start = time.perf_counter()
    for path in paths:
        _library_run(path)
    sequential = time.perf_counter() - start
    with ProcessPoolExecutor(max_workers=workers) as pool:
        list(pool.map(_library_run, paths[:workers]))  # start the workers
        start = time.perf_counter()
        list(pool.map(_library_run, paths))
        parallel = time.perf_counter() - start
    return {"scenarios": len(paths), "runs_per_s_1_process": round(len(paths) / sequential, 2),
            f"runs_per_s_{workers}_processes": round(len(paths) / parallel, 2)}


def identification_time(runs):
    """Median time [s] of the 4-load constant-load fit (808 noisy points, seeded)."""
    from sma_fmu.identification.constant_load import fit_constant_load
    from sma_fmu.identification.measurements import read_constant_load
    from sma_fmu.wire.parameter_file import load_parameters
    from sma_fmu.identification.synthetic import constant_load_rows, write_rows

    params = load_parameters()
    with tempfile.TemporaryDirectory() as folder:
        path = write_rows(Path(folder) / "sweeps.csv", constant_load_rows(
            params, [3.2e-3, 0.05, 0.15, 0.25], noise_ohm=0.05, noise_K=0.3, seed=1))
        seconds = []
        for _ in range(runs):
            start = time.perf_counter()
            fit_constant_load(read_constant_load([path]), params)
            seconds.append(time.perf_counter() - start)
    return round(_median(seconds), 4)


def python_loop_ns(iterations=2_000_000):
    """Machine baseline: ns per iteration of a plain Python multiply-add loop."""
    start = time.perf_counter()
    x = 0.0
    for i in range(iterations):
        x = x * 0.999 + 1.0
    return round((time.perf_counter() - start) / iterations * 1e9, 2)


def _build_trivial(folder):
    from pythonfmu.builder import FmuBuilder
    script = Path(folder) / "trivial_benchmark_slave.py"
    script.write_text(_TRIVIAL_SLAVE, encoding="utf-8")
    return Path(FmuBuilder.build_FMU(script, dest=Path(folder) / "Trivial.fmu"))


def run_batch_benchmark(out_dir, quick=False, progress=print):
    """Only the batch engine's section (``sma-fmu bench --only batch``); written as JSON too."""
    from sma_fmu.studies.batch_benchmark import batch_throughput
    options = dict(sizes=(1, 100, 1000), scalar_runs=4) if quick else {}
    results = {"runs": 1, "batch_engine": batch_throughput(progress=progress, **options)}
    with staged_folder(out_dir) as stage:
        (stage / "benchmark.json").write_text(json_text(results), encoding="utf-8")
    return results


def run_benchmarks(out_dir, runs=5, progress=print):
    """Run every benchmark; returns the results (also written to out_dir/benchmark.json)."""
    from sma_fmu.studies.batch_benchmark import batch_throughput
    if runs < 1:
        raise ValueError(f"runs must be >= 1, got {runs!r}")
    with staged_folder(out_dir) as stage, tempfile.TemporaryDirectory() as folder:
        progress("building the FMUs ...")
        fmu_paths = build_fmus(stage / "fmus")
        fmu_paths["Trivial (baseline)"] = _build_trivial(folder)
        progress(f"FMU step costs ({runs} runs) ...")
        steps = fmu_step_costs(fmu_paths, runs)
        progress(f"SmaActuator in C hosts ({runs} runs of {C_HOST_STEPS} steps per host) ...")
        c_hosts = c_host_step_costs(fmu_paths["SmaActuator"], runs, folder)
        machine = {"python": platform.python_version(), "system": platform.platform(),
                   "python_loop_ns_per_iteration": python_loop_ns()}
        progress(f"native C FMU floor, C host and fmpy master ({runs} alternating runs) ...")
        from sma_fmu.wire.parameter_file import load_parameters
        floor = floor_costs(fmu_paths, load_parameters(), runs, folder)
        progress(f"native (C) FMUs: plant step and HIL closed loop ({runs} alternating runs) ...")
        from sma_fmu.bench.native import native_section
        native = native_section(fmu_paths, load_parameters(), runs, folder)
        progress(f"closed loops, load-step 30 s ({runs} alternating runs per controller and path) ...")
        loops = closed_loop_times(stage / "fmus", runs)
        progress("library throughput over the shipped scenarios ...")
        throughput = library_throughput()
        progress("identification ...")
        results = {
            "machine": machine, "runs": runs, "fmu_step": steps, "c_host_step": c_hosts,
            "floor": {"samples_us": floor["samples"], "not_built": floor["floor"]},
            "ratios": ratio_table(loops, floor),
            "closed_loop_load_step_30s": loops, "library_throughput": throughput,
            "identification_4_loads_s": identification_time(runs), "targets": TARGETS,
            "native": native,
            # --runs 1 or 2 is a smoke run: 1 s batch runs, where the setup weighs more
            "batch_engine": batch_throughput(stop_time_s=5.0 if runs >= 3 else 1.0,
                                             progress=progress),
        }
        (stage / "benchmark.json").write_text(json_text(results), encoding="utf-8")
    return results


def _verdict(value, target, larger_is_better=False):
    met = value >= target if larger_is_better else value <= target
    return f"{'meets' if met else 'MISSES'} target {'>=' if larger_is_better else '<='} {target:g}"


def format_table(results):
    """The results as plain-text tables, with each target's verdict."""
    from sma_fmu.studies.batch_benchmark import format_batch
    if "fmu_step" not in results:                  # --only batch
        return "\n".join(format_batch(results["batch_engine"]))
    lines = [f"sma-fmu benchmark (median of {results['runs']} runs; Python "
             f"{results['machine']['python']}; plain Python loop "
             f"{results['machine']['python_loop_ns_per_iteration']} ns/iteration)", "",
             "FMU per step [us]       doStep  set+doStep+get  (same via fmpy FMU2Slave API)"]
    for name, cost in results["fmu_step"].items():
        lines.append(f"{name:<22}{cost['doStep_us']:>8.2f}{cost['set_doStep_get_us']:>16.2f}"
                     f"{cost['fmpy_api_set_doStep_get_us']:>16.2f}")
    trivial = results["fmu_step"]["Trivial (baseline)"]["set_doStep_get_us"]
    ff = results["fmu_step"]["SmaFeedforward"]["set_doStep_get_us"]
    lines += [f"SmaFeedforward step: {ff:.2f} us = {ff / trivial:.2f} x trivial FMU; "
              f"{_verdict(ff, TARGETS['feedforward_step_us'])} us", ""]
    lines += _c_host_lines(results)
    lines += [""] + _ratio_lines(results)
    if "native" in results:
        from sma_fmu.bench.native import native_lines
        lines += [""] + native_lines(results["native"])
    lines += ["",
              "load-step, 30 s at 1 ms          wall [s]   x real time   (min ... max of runs)"]
    for name, row in results["closed_loop_load_step_30s"].items():
        lines.append(f"{name:<32}{row['wall_s']:>9.3f}{row['real_time_factor']:>13.1f}"
                     f"   ({row['min_s']:.3f} ... {row['max_s']:.3f})")
    loop = results["closed_loop_load_step_30s"]
    fmu_wall = max(v["wall_s"] for k, v in loop.items() if k.endswith("(fmu)"))
    library_factor = min(v["real_time_factor"] for k, v in loop.items() if k.endswith("(library)"))
    throughput = results["library_throughput"]
    lines += [f"slowest FMU closed loop {fmu_wall:.3f} s: {_verdict(fmu_wall, TARGETS['closed_loop_fmu_s'])} s",
              f"slowest library run {library_factor:.0f} x real time: "
              f"{_verdict(library_factor, TARGETS['library_real_time_factor'], True)}", "",
              f"library batch ({throughput['scenarios']} scenarios): "
              + ", ".join(f"{v} {k.replace('_', ' ')}" for k, v in throughput.items() if k != "scenarios"),
              f"identification, 4 loads, 808 points: {results['identification_4_loads_s']:.3f} s: "
              f"{_verdict(results['identification_4_loads_s'], TARGETS['identification_s'])} s",
              ""] + format_batch(results["batch_engine"])
    return "\n".join(lines)


def _c_host_lines(results):
    """The C-host table and its verdict against the fmpy master."""
    lines = ["SmaActuator in C hosts [us per step]                 mean     p50     p99   p99.9"]
    for name, cost in results["c_host_step"].items():
        lines.append(f"{name:<50}{cost['mean_us']:>8.2f}{cost['p50_us']:>8.2f}{cost['p99_us']:>8.2f}"
                     f"{cost['p99_9_us']:>8.1f}")
    after = results["c_host_step"]["plain C host, front (after)"]["mean_us"]
    fmpy = results["fmu_step"]["SmaActuator"]["set_doStep_get_us"]
    ratio = after / fmpy
    lines.append(f"plain C host (front) {after:.2f} us = {ratio:.2f} x the fmpy master's {fmpy:.2f} us: "
                 f"{_verdict(ratio, TARGETS['c_host_vs_fmpy'])}")
    return lines


def _ratio_lines(results):
    """The FMU-path ratios, with the spread of the alternating runs and their targets."""
    lines = [f"Ratios (median of {results['runs']} alternating runs, min ... max)"]
    for name, row in results["ratios"].items():
        target = next((t for key, t in RATIO_TARGETS.items() if name.startswith(key)), None)
        verdict = ""
        if target is not None:
            verdict = f"  {_verdict(row['median'], target[0])}"
            if target[1] is not None:
                verdict += f" (stretch {target[1]:g}: {'met' if row['median'] <= target[1] else 'not met'})"
        lines.append(f"{name:<58}{row['median']:>8.2f} x  ({row['min']:.2f} ... {row['max']:.2f}){verdict}")
    samples = results["floor"]["samples_us"]
    lines.append("per step [us, median]: " + "; ".join(
        f"{name} {_median(values):.3f}" for name, values in samples.items()))
    if results["floor"]["not_built"]:
        lines.append(f"native C FMU (the floor) not built: {results['floor']['not_built']}")
    return lines


def main(out_dir="results/benchmark", runs=5, only=None, quick=False):
    """Run (everything, or ``only="batch"``), print the table, write JSON; returns 0."""
    say = lambda text: print(text, flush=True)  # noqa: E731
    results = (run_batch_benchmark(out_dir, quick, say) if only == "batch"
               else run_benchmarks(out_dir, runs, progress=say))
    print(format_table(results))
    print(f"written: {Path(out_dir) / 'benchmark.json'}")
    return 0
