"""The native (C) family in ``sma-fmu bench``: what a step costs without Python.

Alternating runs (each ratio compares runs made next to each other), all at
:data:`~.c_hosts.BENCH_P_IN_W` and :data:`~.c_hosts.BENCH_LOAD_KG`:
- the library's plant step (PlantStepper.step, Python);
- SmaActuator's set P_in + doStep + get T in the plain C host (``fmi_host.c``): the native
  FMU, and the pythonfmu FMU (its front) in the same host;
- the native SmaActuator through the fmpy master's :class:`~sma_fmu.cosim.master.LeanStep`
  (ctypes: each call costs about a microsecond, which bounds the gain there).
And the HIL case: the five native FMUs (signals, compensator, PI, PWM driver, plant) as a
sequential loop in the plain C loop host (``loop_host.c``, no Python in the process),
:data:`LOOP_STEPS` steps of 1 ms of the PWM set-point scenario, each step timed. And the C
master against the library per scenario, recording included (:mod:`.c_master`).
"""
import dataclasses
import statistics
from pathlib import Path

from sma_fmu.bench.c_hosts import (BENCH_LOAD_KG, _library_plant_step_us, _master_step_us,
                                   _references, plain_host_step_us)

__all__ = ["LOOP_STEPS", "LOOP_SCENARIO", "NATIVE_TARGETS", "native_costs", "native_lines",
           "native_section"]

LOOP_STEPS = 1_000_000
LOOP_SCENARIO = "setpoints-pwm-pi+ff-adaptive"  # all five FMUs
NATIVE_TARGETS = {  # the C family's speed targets: (target, "<=" or ">=")
    "native SmaActuator in the C host / library plant step": (0.1, "<="),
    "pythonfmu / native SmaActuator, both in the C host": (20.0, ">="),
    "native closed loop in the C host, p99.9 [us]": (10.0, "<"),
}


def _loop_timing(native_paths, folder, steps):
    """{p50_us, p99_us, p99_9_us, max_us, total_s} of the native closed loop in the loop host."""
    from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios
    from sma_fmu.systems.closed_loop import closed_loop
    from sma_fmu.systems.loop_host import run_loop_host

    scenario = load_scenario(resolve_scenarios([LOOP_SCENARIO])[0])
    scenario = dataclasses.replace(scenario, stop_time_s=steps * scenario.step_s)
    system = closed_loop(scenario, Path(native_paths["SmaActuator"]).parent)
    _, logs, timing = run_loop_host(system, steps, folder, timing=True)
    errors = [text for status, _, text in logs if status >= 2]
    if errors:
        raise RuntimeError(f"the native closed loop logged: {errors[0]}")
    return timing


def native_costs(python_paths, native_paths, params, runs, folder, loop_steps=LOOP_STEPS):
    """Alternating runs of the cases above: {"samples_us": {case: [us per run]},
    "ratios": {name: {median, min, max, runs}}, "loop": {statistic: median of the runs},
    "loop_runs": [timing per run], "loop_steps": n}."""
    folder = Path(folder)
    native, python = native_paths["SmaActuator"], python_paths["SmaActuator"]
    refs = _references(native)
    cases = {
        "library plant step": lambda: _library_plant_step_us(params),
        "native SmaActuator, C host": lambda: plain_host_step_us(native, 1, folder / "native", refs)[0],
        "pythonfmu SmaActuator, C host": lambda: plain_host_step_us(python, 1, folder / "python", refs)[0],
        "native SmaActuator, fmpy master": lambda: _master_step_us(native, {"load": BENCH_LOAD_KG}),
    }
    samples = {name: [] for name in cases}
    loops = []
    for run in range(runs):
        for name, measure in cases.items():
            samples[name].append(measure())
        loops.append(_loop_timing(native_paths, folder / f"loop{run}", loop_steps))
    plant = samples["library plant step"]
    pairs = {
        "native SmaActuator in the C host / library plant step": ("native SmaActuator, C host", plant),
        "pythonfmu / native SmaActuator, both in the C host": (
            "pythonfmu SmaActuator, C host", samples["native SmaActuator, C host"]),
        "native SmaActuator in the fmpy master / library plant step": (
            "native SmaActuator, fmpy master", plant),
    }
    ratios = {}
    for name, (case, base) in pairs.items():
        values = [a / b for a, b in zip(samples[case], base)]
        ratios[name] = {"median": round(statistics.median(values), 4), "min": round(min(values), 4),
                        "max": round(max(values), 4), "runs": len(values)}
    loop = {key: round(statistics.median(t[key] for t in loops), 4) for key in loops[0]}
    return {"samples_us": samples, "ratios": ratios, "loop": loop, "loop_runs": loops,
            "loop_steps": loop_steps, "loop_scenario": LOOP_SCENARIO}


def _verdict(value, target):
    limit, sense = target
    met = {"<=": value <= limit, ">=": value >= limit, "<": value < limit}[sense]
    return f"{'meets' if met else 'MISSES'} target {sense} {limit:g}"


def native_lines(native):
    """The native section of the benchmark table, with its targets."""
    lines = [f"Native (C) FMUs (median of {len(native['loop_runs'])} alternating runs, min ... max)"]
    for name, row in native["ratios"].items():
        target = NATIVE_TARGETS.get(name)
        verdict = f"  {_verdict(row['median'], target)}" if target else "  (ctypes bounds it)"
        lines.append(f"{name:<58}{row['median']:>8.3f} x  ({row['min']:.3f} ... {row['max']:.3f}){verdict}")
    lines.append("per step [us, median]: " + "; ".join(
        f"{name} {statistics.median(values):.3f}" for name, values in native["samples_us"].items()))
    loop = native["loop"]
    name = "native closed loop in the C host, p99.9 [us]"
    lines.append(f"native closed loop in the C host ({native['loop_scenario']}, 5 FMUs, "
                 f"{native['loop_steps']} steps of 1 ms): per step p50 {loop['p50_us']:.3f} us, "
                 f"p99 {loop['p99_us']:.3f} us, p99.9 {loop['p99_9_us']:.3f} us, max {loop['max_us']:.1f} us: "
                 f"{_verdict(loop['p99_9_us'], NATIVE_TARGETS[name])} us")
    if "c_master" in native:  # the scenario's loop in the C master, recorded
        from sma_fmu.bench.c_master import c_master_lines
        lines += [""] + c_master_lines(native["c_master"])
    return lines


def native_section(python_paths, params, runs, folder):
    """Build the native FMUs (sma-fmu build --native) into ``folder`` and time them
    (:func:`native_costs`); the hook of :func:`~.benchmark.run_benchmarks`."""
    import warnings
    from sma_fmu.fmi.packaging.c_family_build import NativeBuildWarning, build_native_fmus

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NativeBuildWarning)  # win64 is not timed here
        native_paths = build_native_fmus(Path(folder) / "native-fmus")
    costs = native_costs(python_paths, native_paths, params, runs, folder)
    from sma_fmu.bench.c_master import c_master_times
    costs["c_master"] = c_master_times(Path(native_paths["SmaActuator"]).parent, runs,
                                       Path(folder) / "c-master")
    return costs
