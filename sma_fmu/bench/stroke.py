"""The stroke map in ``sma-fmu bench --only stroke``: what mapping a stroke reference to R_ref
costs per step in the Python runtime (:mod:`sma_fmu.runtime.stroke`).

- a held reference (the load and stroke unchanged: the map's kept target);
- a moving stroke on the reference wire (no thermal expansion: the closed form);
- a moving stroke on the Flexinol fit (two stages, thermal expansion: the bracketed fixed
  point over the branch inverse), with the rounds it takes;
- R_ref(t) of the shipped 0.5 Hz stroke profile, step by step (the trend and the map);
- the two shipped stroke scenarios on the library path against the same runs with the
  mapped R_ref given as a table (what the mapping adds to a whole run), wall time;
- with native FMUs (``--fmus``): the same scenarios through the C master against the library
  path (:func:`~sma_fmu.bench.c_master.c_master_times`, recording included; the C master's
  wall includes its mapping of the stroke into the signals FMU's table, done in C:
  :mod:`sma_fmu.cosim.stroke_table`).

CPU time per step, the median of the passes (a shared machine's other work is not counted);
the moving strokes in C too (``stroke_timing.c`` compiled with the C family's sources: the
C runtime's stroke map, bit-equal to Python's), and the profile's R_ref(t) as the C master's
stroke table computes it (the whole program's CPU per step).
"""
import dataclasses
import resource
import shutil
import statistics
import subprocess
import tempfile
import time

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.cosim.stroke_table import stroke_table_input, stroke_table_program
from sma_fmu.files.json_output import json_text
from sma_fmu.files.output_folder import staged_folder
from sma_fmu.files.package_data import shipped_file
from sma_fmu.bench.inverse import timing_program
from sma_fmu.fmi.packaging.runtime_program import wire_numbers
from sma_fmu.runtime import stroke as stroke_module
from sma_fmu.runtime.stroke import StrokeMap, start_length
from sma_fmu.wire.parameter_file import load_parameter_set

__all__ = ["SCENARIOS", "STEPS", "map_costs", "c_map_ns", "c_table_ns", "c_map_costs", "scenario_walls",
           "run_stroke_bench", "stroke_lines"]

SCENARIOS = ("flexinol-stroke-load-step-pi+ff-adaptive", "flexinol-stroke-profile-pi+ff-adaptive")
STEPS = 2000     # map calls per pass


def _median_ns(call, passes):
    costs = []
    for _ in range(passes):
        start = time.process_time()
        for k in range(STEPS):
            call(k)
        costs.append((time.process_time() - start) / STEPS * 1e9)
    return statistics.median(costs)


def _rounds(stroke_map, strokes, load):
    """Mean branch inverses per solve [1], counted by wrapping the map's inverse."""
    count = [0]
    original = stroke_module.temperature_of_fractions

    def counted(*arguments):
        count[0] += 1
        return original(*arguments)
    stroke_module.temperature_of_fractions = counted
    try:
        for stroke in strokes:
            stroke_map._solve(stroke, stroke_map._branches.get(load, 1))
    finally:
        stroke_module.temperature_of_fractions = original
    return count[0] / len(strokes)


def map_costs(passes):
    """{case: CPU ns per step} and the Flexinol map's mean branch inverses per solve."""
    reference = load_parameter_set().params
    flexinol = load_parameter_set(shipped_file("models", "flexinol_fit.toml")).params
    plain = StrokeMap(reference, start_length(reference, None, 0.05))
    fitted = StrokeMap(flexinol, start_length(flexinol, None, 0.1))
    profile = load_scenario(shipped_file("scenarios", f"{SCENARIOS[1]}.toml")).reference
    strokes = [7e-3 + 16e-3 * k / STEPS for k in range(STEPS)]
    costs = {
        "held (reference and load unchanged)": _median_ns(lambda k: fitted.target(15e-3, 0.2, 1),
                                                          passes),
        "moving stroke, reference wire (closed form)": _median_ns(
            lambda k: plain.target(strokes[k] - 2e-3, 0.05, 1), passes),
        "moving stroke, Flexinol fit (secant on T)": _median_ns(
            lambda k: fitted.target(strokes[k], 0.2, 1), passes),
        "R_ref(t) of the 0.5 Hz profile (trend + map)": _median_ns(
            lambda k: profile.value(k * 1e-3), passes),
    }
    return costs, _rounds(fitted, strokes, 0.2)


def c_map_ns(program, stroke_map, load, direction, strokes, passes):
    """Median CPU time [ns] of one C mapping (``program``: stroke_timing) of ``strokes`` [m]."""
    numbers = wire_numbers(stroke_map.params) + [stroke_map.start_length, load, direction, passes, len(strokes), *strokes]
    result = subprocess.run([str(program)], input=" ".join(map(repr, numbers)),
                            capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"the stroke timing program failed: {result.stderr.strip()}")
    return statistics.median(float(line.split()[0]) for line in result.stdout.splitlines())


def c_table_ns(program, scenario, passes):
    """Median CPU time [ns per step] of the C master's stroke table of ``scenario`` (``program``:
    :func:`~sma_fmu.cosim.stroke_table.stroke_table_program`): the whole process's CPU (its
    start and reading its input included) over the run's steps."""
    text, costs = stroke_table_input(scenario).encode("ascii"), []
    for _ in range(passes):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([str(program)], input=text, capture_output=True, check=True)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        costs.append(cpu / (scenario.steps + 1) * 1e9)
    return statistics.median(costs)


def c_map_costs(passes):
    """{case: C CPU ns per mapping} of the two moving-stroke cases of :func:`map_costs` and
    the 0.5 Hz profile's R_ref(t) as the C master maps it (:func:`c_table_ns`)."""
    reference = load_parameter_set().params
    flexinol = load_parameter_set(shipped_file("models", "flexinol_fit.toml")).params
    strokes = [7e-3 + 16e-3 * k / STEPS for k in range(STEPS)]
    profile = load_scenario(shipped_file("scenarios", f"{SCENARIOS[1]}.toml"))
    with tempfile.TemporaryDirectory() as folder:
        program = timing_program(folder, "stroke_timing")
        return {
            "R_ref(t) of the 0.5 Hz profile (trend + map)": c_table_ns(
                stroke_table_program(folder), profile, passes),
            "moving stroke, reference wire (closed form)": c_map_ns(
                program, StrokeMap(reference, start_length(reference, None, 0.05)), 0.05, 1,
                [s - 2e-3 for s in strokes], passes),
            "moving stroke, Flexinol fit (secant on T)": c_map_ns(
                program, StrokeMap(flexinol, start_length(flexinol, None, 0.1)), 0.2, 1,
                strokes, passes)}


def scenario_walls(runs):
    """{scenario: (stroke run [s], the same with the mapped R_ref as a table [s])}, medians."""
    walls = {}
    for name in SCENARIOS:
        scenario = load_scenario(shipped_file("scenarios", f"{name}.toml"))
        table = _as_table(scenario)
        stroke, plain = [], []
        for _ in range(runs):
            stroke.append(run_library(scenario).wall_time_s)
            plain.append(run_library(table).wall_time_s)
        walls[name] = (statistics.median(stroke), statistics.median(plain))
    return walls


class _Sampled:
    """R_ref sampled once per step of a run, looked up by time (no mapping during the run)."""

    def __init__(self, scenario):
        h = scenario.step_s
        self.values = [scenario.reference.value(k * h) for k in range(scenario.steps + 1)]
        self.h = h

    def value(self, t):
        return self.values[int(round(t / self.h))]


def _as_table(scenario):
    return dataclasses.replace(scenario, reference=_Sampled(scenario))


def run_stroke_bench(out_dir, runs, progress=print, fmus=None):
    """Measure; write ``benchmark.json`` into ``out_dir``; return the results. ``fmus``: a
    folder of native FMUs for the C master's runs (None: none)."""
    progress("the stroke map per step (Python) ...")
    costs, rounds = map_costs(max(runs, 3))
    progress("the stroke map per step (C) ...")
    c_costs = c_map_costs(max(runs, 5) * 4)
    progress("the stroke scenarios on the library path ...")
    walls = scenario_walls(runs)
    results = {"map_ns_per_step": costs, "c_map_ns_per_step": c_costs,
               "flexinol_inverses_per_solve": rounds,
               "library_wall_s": {name: {"stroke": a, "mapped_beforehand": b}
                                  for name, (a, b) in walls.items()}}
    with staged_folder(out_dir) as stage:
        if fmus is not None:
            from sma_fmu.bench.c_master import c_master_times
            progress("the stroke scenarios through the C master ...")
            results["c_master"] = c_master_times(fmus, runs, stage / "runs", SCENARIOS,
                                                 ("csv",))
            shutil.rmtree(stage / "runs", ignore_errors=True)
        (stage / "benchmark.json").write_text(json_text(results), encoding="utf-8")
    return results


def stroke_lines(results):
    """The printed table of :func:`run_stroke_bench`'s results."""
    c_costs = results.get("c_map_ns_per_step", {})
    lines = ["stroke map, CPU per step: Python runtime / C runtime"]
    for case, ns in results["map_ns_per_step"].items():
        c = c_costs.get(case)
        lines.append(f"  {case:<48} {ns / 1e3:>8.2f} us" +
                     ("" if c is None else f" / {c / 1e3:.3f} us"))
    lines.append(f"  Flexinol fit: {results['flexinol_inverses_per_solve']:.1f} branch inverses "
                 f"per solve (mean over 7-23 mm at 0.2 kg)")
    lines.append("library path, wall [s] (median): stroke run / R_ref mapped beforehand")
    for name, walls in results["library_wall_s"].items():
        lines.append(f"  {name:<48} {walls['stroke']:>7.2f} / {walls['mapped_beforehand']:.2f}")
    if "c_master" in results:
        lines.append("C master / library path, wall [s] (median, csv recorded; the C master's "
                     "includes mapping the stroke, in C)")
        for name, times in results["c_master"].items():
            lines.append(f"  {name:<48} {times['c_s']:>7.2f} / {times['library_s']:.2f}  "
                         f"ratio {times['ratio']:.3f} ({times['min']:.3f}-{times['max']:.3f})")
    return lines
