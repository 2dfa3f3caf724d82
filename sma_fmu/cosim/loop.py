"""The closed loop of the paper's Fig. 9, sequenced as in spec section 11, for any plant/compensator.

One loop serves both paths: the FMU path (:mod:`sma_fmu.cosim.master`, plant and compensator
are FMUs under fmpy) and the library path (here, the runtime steppers directly). Per
step k = 0 ... n-1 (t_k = k h): read R_k; e_k = R_k - R_ref(t_k); the compensator takes
R_ref(t_k), f(t_k) -> u_ff,k; the PI gives u_k = max(0, u_ff,k + Kp e_k + Ki I_k); the plant
steps t_k -> t_k+1 with u_k and f(t_k) held. Sample n records R_n and T_n only.

That is Gauss-Seidel coupling (``coupling="gauss-seidel"``, the default): each block sees
the outputs computed before it in the same step. SSP hosts (libcosim, Ecos) couple by
Jacobi (``coupling="jacobi"``): all blocks step together, each with the outputs the others
had at t_k, so the PI gets u_ff,k-1 and the plant gets u_k-1 (at k = 0: the outputs after
initialization, u_ff of the first sample and the PI's output before its first step).
The signals R_ref(t_k), f(t_k) and R_k reach the blocks alike in both.

A scenario with a PWM drive (``[drive] kind = "pwm"``) puts a driver between the PI and the
plant: the driver gets the PI's (clamped) output u_k as its demand and the plant gets the
driver's output, the exact mean of the PWM wave over the step (:mod:`sma_fmu.runtime.pwm`).
Gauss-Seidel: PI -> driver -> plant in the same step, the plant gets PWM(u_k) over
[t_k, t_k+1). Jacobi: the driver gets the PI's output held from the step before (u_k-1; at
k = 0 the PI's output before its first step) and the plant the driver's output from the
step before, so the power reaches the wire one step later than without a driver; at k = 0
the plant gets the driver's output after initialization (0 W for the PWM driver). The P
column is the power the plant applied in both.

A driver's current or voltage limit (``[drive] I_max_A``, ``V_max_V``) cuts the power to
min(I_max^2 R_k, V_max^2 / R_k) with the wire's R_k at t_k (:mod:`sma_fmu.runtime.drive_limit`):
the PWM wave's on-power, or, for kind "power", the demand itself (a linear driver).

A ``[sensor]`` puts the controller's measurement between the plant and the PI: the PI's
error is e_k = R_meas,k - R_ref(t_k), R_meas,k the reading of sample k
(:class:`~sma_fmu.runtime.measurement.ResistanceSensor`: noise, ADC); the R column and the
metrics stay the wire's true R.

The driver is any object with

- ``step(time_s, demand_W, step_size) -> P_in``: the power [W] the plant gets over
  [time_s, time_s + step_size) for the demand ``demand_W`` [W] held over that step; for a
  scenario whose drive has a limit, ``step(time_s, demand_W, step_size, resistance)``, the
  wire at ``resistance`` [ohm] (R_k) at the step's start;
- ``initial() -> P_in``: its output [W] after initialization, before its first step (what a
  Jacobi host passes to the plant at k = 0);

:class:`LibraryDriver` (the runtime :class:`~sma_fmu.runtime.pwm.PwmDriver`) is one; an
FMU master passes its own as ``run_loop(..., driver=...)``.
"""
import math
import time
from dataclasses import dataclass, field

import numpy as np

from sma_fmu.cosim.run_warnings import WarningTexts, ordered
from sma_fmu.runtime.drive_limit import DriveLimit, LinearDriver
from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.measurement import ResistanceSensor
from sma_fmu.runtime.pi_control import PIController
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.pwm import PwmDriver

__all__ = ["COLUMNS", "COLUMN_NAMES", "TIMESERIES_DTYPE", "PLANT_OUTPUTS", "COUPLINGS",
           "LoopResult", "run_loop", "LibraryPlant", "LibraryCompensator", "LibraryDriver",
           "library_driver", "library_sensor", "run_library"]

COLUMNS = (("t", "s"), ("R_ref", "ohm"), ("R", "ohm"), ("T", "degC"), ("T_ref", "degC"),
           ("x", "m"), ("stroke", "m"), ("xi_P", ""), ("xi_M", ""), ("xi_F", ""),
           ("P_ff", "W"), ("P_fb", "W"), ("P", "W"), ("load", "kg"), ("saturated", ""))
COLUMN_NAMES = tuple(f"{name}_{unit}" if unit else name for name, unit in COLUMNS)  # CSV header
TIMESERIES_DTYPE = [(name, bool if name == "saturated" else float) for name, _ in COLUMNS]
PLANT_OUTPUTS = ("R", "T", "x", "xi_P", "xi_M", "xi_F", "P")  # what a loop plant returns
COUPLINGS = ("gauss-seidel", "jacobi")
ROWS_PER_CHUNK = 4096   # rows gathered as tuples before they go into the result array


@dataclass
class LoopResult:
    """Time series of one run: ``data`` is a structured array with the fields of :data:`COLUMNS`
    (None when the run streamed its rows to a sink); ``warnings`` the model's warnings [str]
    the run gave, each once (:mod:`sma_fmu.cosim.run_warnings`; none from the system hosts)."""

    scenario: object
    data: np.ndarray
    path: str
    wall_time_s: float
    warnings: list = field(default_factory=list)


class LibraryPlant:
    """The plant as the runtime :class:`PlantStepper` (library path); ``warnings`` the
    :class:`~sma_fmu.cosim.run_warnings.WarningTexts` of its start and steps."""

    def __init__(self, scenario):
        self.stepper = PlantStepper(scenario.params, scenario.T_start, scenario.hysteresis_mode,
                                    scenario.load.value(0.0))
        self.warnings = WarningTexts()
        if self.stepper.warning is not None:   # what an FMU logs at exitInitializationMode
            self.warnings.add(self.stepper.warning)

    def outputs(self):
        """The :data:`PLANT_OUTPUTS` now."""
        return self.stepper.outputs[:7]

    def step(self, time_s, power, load, step_size):
        """Advance one step; returns the :data:`PLANT_OUTPUTS` at its end."""
        stepper = self.stepper
        outputs = stepper.step(power, load, step_size)
        if stepper.warning is not None:
            self.warnings.add(stepper.warning)
        return outputs[:7]

    def close(self):
        """Nothing to release."""


class LibraryCompensator:
    """The compensator as the runtime :class:`FeedforwardStepper` (library path); ``warnings``
    the :class:`~sma_fmu.cosim.run_warnings.WarningTexts` of its steps."""

    def __init__(self, scenario):
        c = scenario.controller
        self.stepper = FeedforwardStepper(scenario.compensator_params, c.alpha, c.beta,
                                          c.model_load, c.adapt_to_load, c.inverse, c.shaping,
                                          c.power_cap_W, c.anticipation_s)
        self.warnings = WarningTexts()   # (its start sets none: initial_outputs warns of nothing)

    def initial(self, reference, load):
        """(P_ff [W], T_ref [degC], saturated) before the first step (what a Jacobi host passes on)."""
        return self.stepper.initial_outputs(reference, load)

    def step(self, time_s, reference, load, step_size):
        """(P_ff [W], T_ref [degC], saturated) for the sample at ``time_s``."""
        stepper = self.stepper
        outputs = stepper.step(reference, load, step_size)
        if stepper.warning is not None:
            self.warnings.add(stepper.warning)
        return outputs

    def close(self):
        """Nothing to release."""


class LibraryDriver:
    """The scenario's drive as the runtime :class:`PwmDriver` or, for kind "power" with a
    limit, :class:`~sma_fmu.runtime.drive_limit.LinearDriver` (library path)."""

    def __init__(self, scenario):
        drive = scenario.drive
        limit = DriveLimit(drive.I_max_A, drive.V_max_V)
        self.pwm = (PwmDriver(drive.frequency_Hz, drive.peak_W, limit) if drive.pwm
                    else LinearDriver(limit))

    def initial(self):
        """P_in [W] after initialization, before the first step: 0 W (the wave's first period
        has not started)."""
        return self.pwm.power

    def step(self, time_s, demand, step_size, resistance=None):
        """P_in [W] over [time_s, time_s + step_size) for ``demand`` [W] with the wire at
        ``resistance`` [ohm]: the mean of the PWM wave, or the demand within the limit."""
        return self.pwm.step(demand, time_s, step_size, resistance)

    def close(self):
        """Nothing to release."""


def library_driver(scenario):
    """The :class:`LibraryDriver` of ``scenario``'s ``[drive]``, or None for kind "power"
    without a limit."""
    return LibraryDriver(scenario) if scenario.drive.driver else None


def library_sensor(scenario):
    """The :class:`ResistanceSensor` of ``scenario``'s ``[sensor]``, or None when ideal."""
    sensor = scenario.sensor
    return None if sensor.ideal else ResistanceSensor(
        sensor.noise_ohm_rms, sensor.full_scale_ohm, sensor.bits, sensor.seed)


def run_loop(scenario, plant, compensator=None, coupling="gauss-seidel", driver=None, sink=None,
             reference_at=None):
    """Close the loop over ``scenario``; returns the structured time-series array.

    ``plant`` has ``outputs()`` and ``step(t, power, load, h)`` returning the
    :data:`PLANT_OUTPUTS` (R, T, x, xi_P, xi_M, xi_F, applied power P); ``compensator``
    (None for the "pi" controller) has ``step(t, R_ref, load, h)`` returning
    (P_ff, T_ref, saturated), and for Jacobi ``initial(R_ref, load)``. ``coupling`` is one
    of :data:`COUPLINGS`. ``driver`` (see the module docstring: ``step(t, demand, h)``,
    ``initial()``) sits between the PI and the plant; None takes :func:`library_driver` of
    the scenario (none for a ``[drive]`` of kind "power": the plant gets the PI's output).
    Row k holds the samples at t_k, the compensator's and the PI's outputs of step k and the
    power the plant applied over [t_k, t_k+1); the stroke is the contraction x_0 - x_k [m]
    (positive: the wire shortened).

    ``sink``: None keeps the whole series and returns it; else a callable that gets the
    rows in blocks of :data:`ROWS_PER_CHUNK` (the last one shorter), as structured arrays
    it may keep, and the run keeps nothing (returns None): memory does not grow with it.
    ``reference_at``: R_ref(t) [ohm] as the loop samples it, when the caller has it in a
    faster form than the scenario's reference (a stroke mapped in C, the same values); None
    takes ``scenario.reference.value``.
    """
    if coupling not in COUPLINGS:
        raise ValueError(f"coupling must be one of {', '.join(COUPLINGS)}, got {coupling!r}")
    jacobi = coupling == "jacobi"
    if driver is None:
        driver = library_driver(scenario)
    h, n = scenario.step_s, scenario.steps
    reference_at = scenario.reference.value if reference_at is None else reference_at
    load_at = scenario.load.value
    if sink is None:  # the result: its memory is all the run keeps
        data = np.empty(n + 1, dtype=TIMESERIES_DTYPE)
    else:
        data = np.empty(ROWS_PER_CHUNK, dtype=TIMESERIES_DTYPE)
    gains = scenario.controller
    pi = PIController(gains.Kp, gains.Ki)
    sensor = library_sensor(scenario)
    measure = None if sensor is None else sensor.measure
    limited = scenario.drive.limited       # the driver takes the wire's R_k
    nan = math.nan
    no_compensator = (0.0, nan, False)
    rows, first_row = [], 0
    append = rows.append
    # the blocks' steps looked up once, not per step
    plant_step, pi_step = plant.step, pi.step
    compensator_step = None if compensator is None else compensator.step
    driver_step = None if driver is None else driver.step
    resistance, temperature, length, xi_p, xi_m, xi_f, _ = plant.outputs()
    start_length = length
    if jacobi:  # what the blocks show after initialization: a Jacobi host passes it on at k = 0
        held_ff = (no_compensator if compensator is None
                   else compensator.initial(reference_at(0.0), load_at(0.0)))
        measured = resistance if sensor is None else sensor.preview(resistance)
        held_power = pi.output(measured - reference_at(0.0), held_ff[0])[0]
        held_drive = None if driver is None else driver.initial()
    for k in range(n):
        time_s = k * h
        reference, load = reference_at(time_s), load_at(time_s)
        error = (resistance if measure is None else measure(resistance)) - reference
        if compensator_step is None:
            compensated = no_compensator
        else:
            compensated = compensator_step(time_s, reference, load, h)
        p_ff, t_ref, saturated = compensated
        if jacobi:  # the PI, the driver and the plant get what their sources had at t_k
            power, feedback = pi_step(error, held_ff[0], h)
            if driver_step is None:
                plant_power = held_power
            else:
                plant_power, held_drive = held_drive, (
                    driver_step(time_s, held_power, h, resistance) if limited
                    else driver_step(time_s, held_power, h))
            held_ff, held_power = compensated, power
        else:
            power, feedback = pi_step(error, p_ff, h)
            if driver_step is None:
                plant_power = power
            elif limited:
                plant_power = driver_step(time_s, power, h, resistance)
            else:
                plant_power = driver_step(time_s, power, h)
        sample = (time_s, reference, resistance, temperature, t_ref, length, start_length - length,
                  xi_p, xi_m, xi_f, p_ff, feedback)
        resistance, temperature, length, xi_p, xi_m, xi_f, applied = plant_step(
            time_s, plant_power, load, h)
        append(sample + (applied, load, saturated))
        if len(rows) == ROWS_PER_CHUNK:  # into the result: a tuple row costs ~5x its 113 bytes
            if sink is None:
                data[first_row:first_row + ROWS_PER_CHUNK] = rows
                first_row += ROWS_PER_CHUNK
            else:
                data[:] = rows
                sink(data)
                data = np.empty(ROWS_PER_CHUNK, dtype=TIMESERIES_DTYPE)
            rows = []
            append = rows.append
    time_s = n * h
    rows.append((time_s, reference_at(time_s), resistance, temperature, nan, length,
                 start_length - length, xi_p, xi_m, xi_f, nan, nan, nan, load_at(time_s), False))
    if sink is None:
        data[first_row:] = rows
        return data
    sink(np.array(rows, dtype=TIMESERIES_DTYPE))
    return None


def run_library(scenario, coupling="gauss-seidel", sink=None):
    """Run ``scenario`` on the library steppers (no FMUs); returns a :class:`LoopResult`.

    ``coupling``: one of :data:`COUPLINGS`; "jacobi" gives what an SSP host computes.
    ``sink``: see :func:`run_loop` (then the result's ``data`` is None).
    """
    start = time.perf_counter()
    plant = LibraryPlant(scenario)
    compensator = LibraryCompensator(scenario) if scenario.controller.feedforward else None
    data = run_loop(scenario, plant, compensator, coupling, sink=sink)
    warnings = {"plant": plant.warnings}
    if compensator is not None:
        warnings["compensator"] = compensator.warnings
    return LoopResult(scenario, data, "library", time.perf_counter() - start, ordered(warnings))
