"""The feedforward compensator's cost per step in ``sma-fmu bench --only hardware``: the paper's
(major inverse and phase-lag filter) beside the new ones (the minor-loop inverse, the demand
shaped into the reachable band, with and without anticipating the lower turn), in the Python
runtime and in the C runtime (``compensator_timing.c`` compiled with the C family's sources).

Each case is the compensator of a shipped bench scenario (:data:`CASES`), as the loop builds
it, stepped through that scenario's own R_ref and load over :data:`STEPS` steps from
:data:`START_S` (two periods of the 0.5 Hz reference, the load stepping at 10 s): CPU time per
step, the median of the passes, a fresh compensator each pass.
"""
import dataclasses
import math
import statistics
import subprocess
import time

from sma_fmu.bench.inverse import timing_program
from sma_fmu.fmi.packaging.runtime_program import wire_numbers
from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios
from sma_fmu.runtime.feedforward import FeedforwardStepper

__all__ = ["CASES", "START_S", "STEPS", "compensator_samples", "python_compensator_ns",
           "python_compensator_sum", "c_compensator_passes", "c_compensator_ns",
           "compensator_costs"]

# case -> (what it is, its scenario, anticipation L [s] instead of the scenario's, or None)
CASES = {
    "paper": ("major inverse + phase-lag filter (paper)", "load-step-bench-pi+ff-adaptive", None),
    "minor_loop": ("minor-loop inverse + phase-lag filter",
                   "load-step-continuous-bench-pi+ff-adaptive-minor-loop", None),
    "shaped": ("shaped (major inverse), no anticipation",
               "load-step-bench-pi+ff-adaptive-reachable", 0.0),
    "anticipating": ("shaped (major), anticipation 0.15 s",
                     "load-step-bench-pi+ff-adaptive-reachable", None),
    "anticipating_minor": ("shaped (minor-loop), anticipation 0.15 s",
                           "load-step-continuous-bench-pi+ff-adaptive-reachable", None)}
START_S = 8.0     # the samples start here [s] ...
STEPS = 4000      # ... and run this many steps (8-12 s: the load steps at 10 s)


def _settings(case):
    """(scenario, {FeedforwardStepper's keyword: value}) of ``case``, as the loop builds it."""
    _, name, lead = CASES[case]
    scenario = load_scenario(resolve_scenarios([name])[0])
    c, params = scenario.controller, scenario.compensator_params
    if lead is not None:
        c = dataclasses.replace(c, anticipation_s=lead)
    return scenario, {
        "alpha": params.phase_lag_alpha if c.alpha is None else c.alpha,
        "beta": params.beta if c.beta is None else c.beta,
        "model_load": params.model_load if c.model_load is None else c.model_load,
        "adapt_to_load": c.adapt_to_load, "inverse": c.inverse, "shaping": c.shaping,
        "power_cap": c.power_cap_W, "anticipation": c.anticipation_s}


def compensator_samples(scenario, start_s=START_S, steps=STEPS):
    """[(R_ref [ohm], load [kg])] of ``scenario`` at t_k = k h over ``steps`` steps from
    ``start_s`` [s]."""
    first = round(start_s / scenario.step_s)
    times = [k * scenario.step_s for k in range(first, first + steps)]
    return [(scenario.reference.value(t), scenario.load.value(t)) for t in times]


def python_compensator_ns(case, passes, steps=STEPS):
    """Median CPU time [ns] of one step of ``case``'s compensator in the Python runtime."""
    scenario, settings = _settings(case)
    samples, h = compensator_samples(scenario, steps=steps), scenario.step_s
    costs = []
    for _ in range(passes):
        stepper = FeedforwardStepper(scenario.compensator_params, **settings)
        start = time.process_time()
        for reference, load in samples:
            stepper.step(reference, load, h)
        costs.append((time.process_time() - start) / len(samples) * 1e9)
    return statistics.median(costs)


def python_compensator_sum(case, steps=STEPS):
    """The sum of P_ff [W] over one pass of ``case``'s Python compensator (what the C
    program's pass sums too)."""
    scenario, settings = _settings(case)
    stepper, total = FeedforwardStepper(scenario.compensator_params, **settings), 0.0
    for reference, load in compensator_samples(scenario, steps=steps):
        total += stepper.step(reference, load, scenario.step_s)[0]
    return total


def c_compensator_passes(program, case, passes, steps=STEPS):
    """[(CPU ns per step, sum of P_ff [W])] of each pass of ``case``'s compensator in the C
    runtime (``program``: compensator_timing)."""
    scenario, s = _settings(case)
    params = scenario.compensator_params
    numbers = wire_numbers(params) + [s["alpha"], s["beta"], s["model_load"], float(s["adapt_to_load"])]
    words = [s["inverse"], s["shaping"]]
    samples = compensator_samples(scenario, steps=steps)
    tail = [math.nan if s["power_cap"] is None else s["power_cap"], s["anticipation"],
            scenario.step_s, passes, len(samples), *(v for pair in samples for v in pair)]
    text = " ".join([*map(repr, numbers), *words, *map(repr, map(float, tail))])
    result = subprocess.run([str(program)], input=text, capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"the compensator timing program failed: {result.stderr.strip()}")
    return [tuple(map(float, line.split())) for line in result.stdout.splitlines()]


def c_compensator_ns(program, case, passes, steps=STEPS):
    """Median CPU time [ns] of one step of ``case``'s compensator in the C runtime."""
    return statistics.median(ns for ns, _ in c_compensator_passes(program, case, passes, steps))


def compensator_costs(folder, passes, steps=STEPS):
    """{case: {"python_ns", "c_ns"}}: CPU ns per step of each of :data:`CASES`."""
    program = timing_program(folder, "compensator_timing")
    return {case: {"python_ns": round(python_compensator_ns(case, passes, steps), 1),
                   "c_ns": round(c_compensator_ns(program, case, max(passes, 5), steps), 2)}
            for case in CASES}
