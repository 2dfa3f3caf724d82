"""Benchmarks: how fast the FMUs step under fmpy (median of several runs, microseconds).

``python benchmarks/run.py`` or ``sma-fmu bench``: prints a table and writes JSON. Speed is
measured here, never asserted in tests.
"""
import json
import math
import platform
import statistics
import time
from pathlib import Path

from .fmu_build import build_fmus
from .fmu_instance import FmuInstance

__all__ = ["fmu_step_costs", "run_benchmarks", "main"]

STEP = 1e-3


def _median_us(samples):
    return statistics.median(samples) * 1e6


def _time_steps(fmu, inputs, outputs, values, steps, with_io):
    start = time.perf_counter()
    t = 0.0
    for k in range(steps):
        if with_io:
            fmu.set_real(inputs, values(k))
        fmu.step(t, STEP)
        if with_io:
            fmu.get_real(outputs)
        t += STEP
    return (time.perf_counter() - start) / steps


FMU_CASES = {
    "SmaActuator": (("P_in", "load"), ("R", "T", "x", "xi_P", "xi_M", "xi_F"),
                    lambda k: (1.9 + 0.9 * math.sin(math.pi * k * STEP), 0.05)),
    "SmaFeedforward": (("R_ref", "load"), ("P_ff", "T_ref"),
                       lambda k: (41.85 + 6.05 * math.cos(math.pi * k * STEP), 0.05)),
}


def fmu_step_costs(fmu_paths, runs=5, steps=2000):
    """Per-step cost [us] of each FMU: {name: {"doStep": median, "set+doStep+get": median}}."""
    results = {}
    for name, (inputs, outputs, values) in FMU_CASES.items():
        costs = {"doStep": [], "set+doStep+get": []}
        for run in range(runs):
            for label, with_io in (("doStep", False), ("set+doStep+get", True)):
                with FmuInstance(fmu_paths[name], f"bench-{run}") as fmu:
                    fmu.set_real(inputs, values(0))
                    costs[label].append(_time_steps(fmu, inputs, outputs, values, steps, with_io))
        results[name] = {label: round(_median_us(samples), 2) for label, samples in costs.items()}
    return results


def run_benchmarks(out_dir, runs=5):
    """Run every benchmark; returns the results dict (also written to out_dir/benchmark.json)."""
    out_dir = Path(out_dir)
    fmu_paths = build_fmus(out_dir / "fmus")
    results = {
        "machine": {"python": platform.python_version(), "processor": platform.processor(),
                    "system": platform.platform()},
        "runs": runs,
        "fmu_step_us": fmu_step_costs(fmu_paths, runs=runs),
    }
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "benchmark.json").write_text(json.dumps(results, indent=2), encoding="utf-8")
    return results


def format_table(results):
    """The results as a plain-text table."""
    lines = ["FMU per-step cost under fmpy (median of %d runs, us)" % results["runs"],
             f"{'FMU':<16}{'doStep':>10}{'set+doStep+get':>18}"]
    for name, costs in results["fmu_step_us"].items():
        lines.append(f"{name:<16}{costs['doStep']:>10.1f}{costs['set+doStep+get']:>18.1f}")
    return "\n".join(lines)


def main(out_dir="results/benchmark", runs=5):
    """Run, print the table, write JSON; returns 0."""
    results = run_benchmarks(out_dir, runs)
    print(format_table(results))
    print(f"written: {Path(out_dir) / 'benchmark.json'}")
    return 0
