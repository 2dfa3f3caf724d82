"""Benchmark of the batch engine: closed-loop steps per second per core, against the scalar
library path, at N = 1, 100, 1,000 and 10,000 runs in one batch (one process, one core).

Two sets of runs: "mixed" (:func:`~sma_fmu.studies.random_set.random_scenarios`: every
shipped controller, pi, pi+ff-fixed, pi+ff-adaptive with the major and with the minor-loop
inverse, in both modes, random gains, loads, wire, with the load step at one time and four
references; the hard case, since the batch pays for every branch of every run) and "gain
grid" (one scenario, random Kp and Ki: what a tuning or a gain sweep runs). Each rate
includes the batch's setup (constants per run and load segment), which weighs less the
longer the runs (5 s by default; the paper's scenarios last 30 s). The scalar rate, on
runs of the same set, is the median of three measurements taken before, between and
after the batch sizes, so a change of machine load shows in both.
Part of ``sma-fmu bench``; alone: ``sma-fmu bench --only batch [--quick]``.
"""
import statistics
import time

from sma_fmu.cosim.loop import run_library
from sma_fmu.studies.batch import run_batch
from sma_fmu.studies.random_set import gain_grid_scenarios, random_scenarios

__all__ = ["SIZES", "TARGET", "batch_throughput", "format_batch"]

SIZES = (1, 100, 1000, 10000)
TARGET = {"N": 1000, "ratio": 50.0}   # the target: at least 50x the scalar path at N = 1,000
SETS = {"mixed": lambda count, seed, stop_time_s: random_scenarios(
            count, seed, stop_time_s, load_step_s=round(0.4 * stop_time_s, 3), references=4),
        "gain grid": gain_grid_scenarios}


def _scalar_rate(scenarios):
    began = time.perf_counter()
    for scenario in scenarios:
        run_library(scenario)
    return len(scenarios) * scenarios[0].steps / (time.perf_counter() - began)


def batch_throughput(sizes=SIZES, stop_time_s=5.0, scalar_runs=8, progress=print):
    """{"sets": {name: [{N, batch, scalar steps/s, ratio}]}, ...}: one measurement per size."""
    results = {}
    for name, make in SETS.items():
        scenarios = make(max(sizes), seed=1, stop_time_s=stop_time_s)
        steps = scenarios[0].steps
        scalar = [_scalar_rate(scenarios[:scalar_runs])]
        rates = {}
        for index, size in enumerate(sizes):
            progress(f"batch engine, {name}, N = {size} ...")
            began = time.perf_counter()
            run_batch(scenarios[:size], "metrics")
            rates[size] = size * steps / (time.perf_counter() - began)
            if index == len(sizes) // 2:
                scalar.append(_scalar_rate(scenarios[scalar_runs:2 * scalar_runs]))
        scalar.append(_scalar_rate(scenarios[:scalar_runs]))
        reference = statistics.median(scalar)
        results[name] = [{"N": size, "batch_steps_per_s": round(rate),
                          "scalar_steps_per_s": round(reference),
                          "ratio": round(rate / reference, 1)} for size, rate in rates.items()]
    return {"stop_time_s": stop_time_s, "step_s": 1e-3, "sets": results, "target": TARGET}


def format_batch(results):
    """Text lines of the throughput table, with the target's verdict."""
    lines = [f"batch engine: closed-loop steps/s per core ({results['stop_time_s']:g} s runs "
             f"at 1 ms; scalar = library path, median of 3)",
             f"{'set':<11}{'N':>7}{'batch':>13}{'scalar':>11}{'ratio':>8}"]
    for name, rows in results["sets"].items():
        for row in rows:
            lines.append(f"{name:<11}{row['N']:>7}{row['batch_steps_per_s']:>13,}"
                         f"{row['scalar_steps_per_s']:>11,}{row['ratio']:>7.1f}x")
    target = results["target"]
    for name, rows in results["sets"].items():
        at = [row for row in rows if row["N"] == target["N"]]
        if at:
            met = at[0]["ratio"] >= target["ratio"]
            lines.append(f"{name} at N = {target['N']}: {at[0]['ratio']:.1f}x: "
                         f"{'meets' if met else 'MISSES'} target >= {target['ratio']:g}x")
    return lines
