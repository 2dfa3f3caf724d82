"""The closed loop of the paper's Fig. 9, sequenced as in spec section 11, for any plant/compensator.

One loop serves both paths: the FMU path (:mod:`sma_fmu.cosim.master`, plant and compensator
are FMUs under fmpy) and the library path (here, the runtime steppers directly). Per
step k = 0 ... n-1 (t_k = k h): read R_k; e_k = R_k - R_ref(t_k); the compensator takes
R_ref(t_k), f(t_k) -> u_ff,k; the PI gives u_k = max(0, u_ff,k + Kp e_k + Ki I_k); the plant
steps t_k -> t_k+1 with u_k and f(t_k) held. Sample n records R_n and T_n only.
"""
import math
import time
from dataclasses import dataclass

import numpy as np

from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.pi_control import PIController
from sma_fmu.runtime.plant import PlantStepper

__all__ = ["COLUMNS", "PLANT_OUTPUTS", "LoopResult", "run_loop", "LibraryPlant", "LibraryCompensator",
           "run_library"]

COLUMNS = (("t", "s"), ("R_ref", "ohm"), ("R", "ohm"), ("T", "degC"), ("T_ref", "degC"),
           ("x", "m"), ("stroke", "m"), ("xi_P", ""), ("xi_M", ""), ("xi_F", ""),
           ("P_ff", "W"), ("P_fb", "W"), ("P", "W"), ("load", "kg"), ("saturated", ""))
_DTYPE = [(name, bool if name == "saturated" else float) for name, _ in COLUMNS]
PLANT_OUTPUTS = ("R", "T", "x", "xi_P", "xi_M", "xi_F", "P")  # what a loop plant returns


@dataclass
class LoopResult:
    """Time series of one run: ``data`` is a structured array with the fields of :data:`COLUMNS`."""

    scenario: object
    data: np.ndarray
    path: str
    wall_time_s: float


class LibraryPlant:
    """The plant as the runtime :class:`PlantStepper` (library path)."""

    def __init__(self, scenario):
        self.stepper = PlantStepper(scenario.params, scenario.T_start, scenario.hysteresis_mode,
                                    scenario.load.value(0.0))

    def outputs(self):
        """The :data:`PLANT_OUTPUTS` now."""
        return self.stepper.outputs[:7]

    def step(self, time_s, power, load, step_size):
        """Advance one step; returns the :data:`PLANT_OUTPUTS` at its end."""
        return self.stepper.step(power, load, step_size)[:7]

    def close(self):
        """Nothing to release."""


class LibraryCompensator:
    """The compensator as the runtime :class:`FeedforwardStepper` (library path)."""

    def __init__(self, scenario):
        c = scenario.controller
        self.stepper = FeedforwardStepper(scenario.params, c.alpha, c.beta, c.model_load,
                                          c.adapt_to_load)

    def step(self, time_s, reference, load, step_size):
        """(P_ff [W], T_ref [degC], saturated) for the sample at ``time_s``."""
        return self.stepper.step(reference, load, step_size)

    def close(self):
        """Nothing to release."""


def run_loop(scenario, plant, compensator=None):
    """Close the loop over ``scenario``; returns the structured time-series array.

    ``plant`` has ``outputs()`` and ``step(t, power, load, h)`` returning the
    :data:`PLANT_OUTPUTS` (R, T, x, xi_P, xi_M, xi_F, applied power P); ``compensator``
    (None for the "pi" controller) has ``step(t, R_ref, load, h)`` returning
    (P_ff, T_ref, saturated). Row k holds the samples at t_k and the powers applied over
    [t_k, t_k+1); the stroke is the contraction x_0 - x_k [m] (positive: the wire shortened).
    """
    h, n = scenario.step_s, scenario.steps
    times = [k * h for k in range(n + 1)]
    references = [scenario.reference.value(t) for t in times]
    loads = [scenario.load.value(t) for t in times]
    gains = scenario.controller
    pi = PIController(gains.Kp, gains.Ki)
    nan = math.nan
    rows = []
    resistance, temperature, length, xi_p, xi_m, xi_f, _ = plant.outputs()
    start_length = length
    for k in range(n):
        time_s, reference, load = times[k], references[k], loads[k]
        error = resistance - reference
        if compensator is None:
            p_ff, t_ref, saturated = 0.0, nan, False
        else:
            p_ff, t_ref, saturated = compensator.step(time_s, reference, load, h)
        power, feedback = pi.step(error, p_ff, h)
        sample = (time_s, reference, resistance, temperature, t_ref, length, start_length - length,
                  xi_p, xi_m, xi_f, p_ff, feedback)
        resistance, temperature, length, xi_p, xi_m, xi_f, applied = plant.step(
            time_s, power, load, h)
        rows.append(sample + (applied, load, saturated))
    rows.append((times[n], references[n], resistance, temperature, nan, length,
                 start_length - length, xi_p, xi_m, xi_f, nan, nan, nan, loads[n], False))
    return np.array(rows, dtype=_DTYPE)


def run_library(scenario):
    """Run ``scenario`` on the library steppers (no FMUs); returns a :class:`LoopResult`."""
    start = time.perf_counter()
    plant = LibraryPlant(scenario)
    compensator = LibraryCompensator(scenario) if scenario.controller.feedforward else None
    data = run_loop(scenario, plant, compensator)
    return LoopResult(scenario, data, "library", time.perf_counter() - start)
