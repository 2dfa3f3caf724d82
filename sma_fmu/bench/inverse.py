"""The two-stage inverse in ``sma-fmu bench --only inverse``: what the compensator's inversion
costs with a second stage, and what it does to a closed loop through the FMUs.

- One inversion (``temperature_of_fractions`` on a major branch, the branch constants built
  once, as a compensator at a steady load) in the Python runtime and in the C runtime
  (``inverse_timing.c`` compiled with the C family's sources), on the reference wire (one
  stage: a closed form) and on a two-stage wire (a root search): CPU ns per inversion, the
  median of the passes.
- :data:`SCENARIO` (30 s, 0.25 kg) through the pythonfmu FMUs built from each wire, the
  two wires alternating run by run: wall and CPU time [s] and their ratios, two-stage over
  reference, with the load average before and after (other work on the machine inflates
  the wall; the CPU time counts this process only).

The two-stage wire is a parameter file (``--model``; the Flexinol fit's identified.toml is
the case this measures), else the reference wire with a broad second stage of the shape the
Flexinol fit gives (:data:`SECOND_STAGE`).
"""
import dataclasses
import os
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from sma_fmu.fmi.packaging.runtime_program import runtime_program, wire_numbers
from sma_fmu.runtime.constant_load import branch_constants, branch_fractions
from sma_fmu.runtime.sensing import temperature_of_fractions

__all__ = ["SCENARIO", "FMUS", "SECOND_STAGE", "default_two_stage", "TARGETS", "inverse_targets",
           "python_inverse_ns", "c_inverse_ns", "inverse_costs", "fmu_walls", "run_inverse_bench",
           "inverse_lines"]

SCENARIO = "heavy-pi+ff-adaptive"
FMUS = ("SmaActuator", "SmaFeedforward")   # the FMUs its fmpy master runs (PI: the master's)
LOAD_KG = 0.25          # the scenario's load: every inversion of the micro-benchmark is there
TARGETS = 1000          # targets per pass, spread over the transformation
C_PASSES = 40
# the Flexinol fit's second stage (w2, widths, centres beside stage 1's), on the reference wire
SECOND_STAGE = {"w2": 0.475, "nu2_h": 56.0, "nu2_c": 52.0, "centre_shift_h": 1.5,
                "centre_shift_c": -3.5}


def default_two_stage(params):
    """The reference wire ``params`` with :data:`SECOND_STAGE` (the same load slopes)."""
    return params.replace(w2=SECOND_STAGE["w2"], nu2_h=SECOND_STAGE["nu2_h"],
                          nu2_c=SECOND_STAGE["nu2_c"],
                          a2_h=params.a_h + SECOND_STAGE["centre_shift_h"], b2_h=params.b_h,
                          a2_c=params.a_c + SECOND_STAGE["centre_shift_c"], b2_c=params.b_c)


def inverse_targets(constants, count=TARGETS):
    """``count`` (xi_MF, xi_P) [1] of the branch ``constants`` at temperatures evenly spread
    from 25 K below its lower centre to 25 K above its upper one."""
    centres = [constants.centre] + ([constants.centre2] if constants.w2 else [])
    low, high = min(centres) - 25.0, max(centres) + 25.0
    return [branch_fractions(low + (high - low) * k / (count - 1), constants)
            for k in range(count)]


def python_inverse_ns(constants, targets, margin, passes):
    """Median CPU time [ns] of one Python inversion over ``passes`` passes of ``targets``."""
    costs = []
    for _ in range(passes):
        start = time.process_time()
        for xi_mf, xi_p in targets:
            temperature_of_fractions(xi_mf, xi_p, constants, margin)
        costs.append((time.process_time() - start) / len(targets) * 1e9)
    return statistics.median(costs)


def timing_program(folder, name="inverse_timing"):
    """The bench's ``<name>.c`` compiled with the C runtime's sources (and the timing programs'
    shared header), kept in ``folder``; its path."""
    return runtime_program(Path(__file__).parent / f"{name}.c", folder, ("timing_input.h",))


def c_inverse_ns(program, params, load, direction, targets, passes=C_PASSES):
    """Median CPU time [ns] of one C inversion (``program`` from :func:`timing_program`)."""
    numbers = wire_numbers(params) + [load, direction, passes, len(targets)] + [v for pair in targets for v in pair]
    result = subprocess.run([str(program)], input=" ".join(map(repr, numbers)),
                            capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"the inverse timing program failed: {result.stderr.strip()}")
    return statistics.median(float(line.split()[0]) for line in result.stdout.splitlines())


def inverse_costs(wires, runs, folder):
    """{wire: {"python_ns", "c_ns"}} for ``wires`` {name: WireParameters}, at
    :data:`LOAD_KG` heating; ``runs`` passes of the Python timing (at least 5). CPU time, not
    wall: on a shared machine it counts only this process's work."""
    program = timing_program(folder)
    results = {}
    for name, params in wires.items():
        constants = branch_constants(LOAD_KG, 1, params)
        targets = inverse_targets(constants)
        results[name] = {
            "python_ns": round(python_inverse_ns(constants, targets, params.saturation_margin,
                                                 max(runs, 5)), 1),
            "c_ns": round(c_inverse_ns(program, params, LOAD_KG, 1, targets), 2)}
    return results


def fmu_walls(scenarios, fmu_folders, runs):
    """({wire: [wall s per run]}, {wire: [CPU s per run]}) of each wire's scenario through its
    FMUs, alternating, after an untimed 0.1-s run of each (the first run in a process loads the
    FMU's Python). The pythonfmu FMUs run in this process, so its CPU time is theirs and the
    master's."""
    from sma_fmu.cosim.master import run_fmus
    for name, scenario in scenarios.items():
        run_fmus(dataclasses.replace(scenario, stop_time_s=0.1), fmu_folders[name])
    walls, cpus = {name: [] for name in scenarios}, {name: [] for name in scenarios}
    for _ in range(runs):
        for name, scenario in scenarios.items():
            start = time.process_time()
            walls[name].append(run_fmus(scenario, fmu_folders[name]).wall_time_s)
            cpus[name].append(time.process_time() - start)
    return walls, cpus


def _ratio(samples):
    """{median, min, max} of the run-by-run ratio two-stage / reference."""
    ratios = [a / b for a, b in zip(samples["two-stage"], samples["reference"])]
    return {"median": round(statistics.median(ratios), 3), "min": round(min(ratios), 3),
            "max": round(max(ratios), 3)}


def run_inverse_bench(out_dir, runs=5, model=None, stop_time_s=None, progress=print):
    """The section (see the module docstring); returns the results (also written to
    ``out_dir``/benchmark.json, the FMUs the scenario needs built into ``out_dir``/fmus-*).
    ``stop_time_s`` [s] shortens the scenario (a quick look)."""
    from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios
    from sma_fmu.files.json_output import json_text
    from sma_fmu.files.output_folder import staged_folder
    from sma_fmu.fmi.packaging.build import build_fmus
    from sma_fmu.wire.parameter_file import load_parameter_set, write_parameter_file

    reference = load_parameter_set()
    if model is not None and not load_parameter_set(model).params.terms.two_stage:
        raise ValueError(f"--model {model}: second_stage.w2 = 0, a one-stage wire; the "
                         f"section measures a two-stage one")
    model = None if model is None else Path(model)
    with staged_folder(out_dir) as stage, tempfile.TemporaryDirectory() as folder:
        if model is None:
            model = write_parameter_file(
                stage / "two_stage_wire.toml", default_two_stage(reference.params),
                "two-stage reference wire", "the reference wire with a broad second stage "
                "(sma-fmu bench --only inverse)")
        two_stage = load_parameter_set(model)
        wires = {"reference": reference, "two-stage": two_stage}
        before = os.getloadavg()[0]
        progress("one inversion, Python and C ...")
        costs = inverse_costs({k: v.params for k, v in wires.items()}, runs, folder)
        scenario = load_scenario(resolve_scenarios([SCENARIO])[0])
        if stop_time_s:
            scenario = dataclasses.replace(scenario, stop_time_s=stop_time_s)
        scenarios, fmus = {}, {}
        for name, parameter_set in wires.items():
            progress(f"building the FMUs of the {name} wire ...")
            fmus[name] = stage / f"fmus-{name}"
            build_fmus(fmus[name], parameter_set.path, names=FMUS)
            scenarios[name] = dataclasses.replace(scenario, parameter_set=parameter_set)
        progress(f"{SCENARIO} through the FMUs ({runs} alternating runs per wire) ...")
        walls, cpus = fmu_walls(scenarios, fmus, runs)
        results = {"inverse": {
            "model": str(Path(out_dir) / model.name if model.parent == stage else model),
            "load_kg": LOAD_KG, "per_inversion": costs,
            "scenario": SCENARIO, "stop_time_s": scenario.stop_time_s, "runs": runs,
            "walls_s": {k: [round(w, 4) for w in v] for k, v in walls.items()},
            "wall_s": {k: round(statistics.median(v), 4) for k, v in walls.items()},
            "cpu_s": {k: round(statistics.median(v), 4) for k, v in cpus.items()},
            "ratio": _ratio(walls), "cpu_ratio": _ratio(cpus),
            "load_average": [round(before, 2), round(os.getloadavg()[0], 2)]}}
        (stage / "benchmark.json").write_text(json_text(results), encoding="utf-8")
    return results


def inverse_lines(results):
    """The section as plain-text lines."""
    section = results["inverse"]
    lines = [f"one inversion at {section['load_kg']} kg, heating [CPU ns]  Python         C",
             *(f"{name:<38}{cost['python_ns']:>10.1f}{cost['c_ns']:>10.2f}"
               for name, cost in section["per_inversion"].items()),
             f"  two-stage wire: {section['model']}", "",
             f"{section['scenario']} ({section['stop_time_s']:g} s) through the pythonfmu "
             f"FMUs (median of {section['runs']} alternating runs; load average "
             f"{section['load_average'][0]:g} before, {section['load_average'][1]:g} after)",
             f"{'':<38}  wall [s]   CPU [s]"]
    lines += [f"{name:<38}{wall:>10.3f}{section['cpu_s'][name]:>10.3f}"
              for name, wall in section["wall_s"].items()]
    wall, cpu = section["ratio"], section["cpu_ratio"]
    lines.append(f"two-stage / reference{'':<17}{wall['median']:>9.2f}x{cpu['median']:>9.2f}x"
                 f"  (wall {wall['min']:.2f} ... {wall['max']:.2f}, CPU {cpu['min']:.2f} ... "
                 f"{cpu['max']:.2f})")
    return lines
