"""The batch engine: N closed loops of spec section 11, advanced in lock-step with numpy.

Runs that share the step and the duration (different gains, filters, loads, references,
wire parameters, hysteresis modes and controllers) go through one loop whose every
quantity is an array of N. Per step k, as :func:`sma_fmu.cosim.loop.run_loop` does it:
e_k = R_k - R_ref(t_k) (with a ``[sensor]``, R_meas,k - R_ref(t_k) for the PI, the metrics
keeping the true R: :mod:`sma_fmu.studies.batch.hardware`); u_k = max(0, u_ff,k + Kp e_k +
Ki I_k), with the integrator held while clamped with e_k <= 0; the plants step with u_k and
f(t_k) held, or, for runs with a PWM drive, with the mean of their PWM wave over the step for
the demand u_k (:mod:`sma_fmu.studies.batch.pwm`; Gauss-Seidel, as the library path's
default), and under a current or voltage limit with that power cut to it at R_k. The results
equal the scalar library path's to rounding (tests/studies/test_batch.py,
tests/runtime/test_pwm.py: <= 1e-10 on every column).

Two ways to record: ``"timeseries"`` keeps every run's full series (the rows of
:data:`~sma_fmu.cosim.loop.COLUMNS`; for a few runs), ``"metrics"`` keeps only the metrics,
accumulated per chunk of steps, so memory does not grow with the duration.

Options the engine does not implement raise :class:`BatchUnsupported` (see
:func:`unsupported_reason`); a run that fails in the batch (the compensator's inverse
diverges, a load beyond the model's range, a non-finite power) is run again on the scalar
path, so its outcome, and its error message, are exactly the scalar path's.
"""
import dataclasses
import functools
import time

import numpy as np

from sma_fmu.cosim.loop import TIMESERIES_DTYPE, run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.scenario import CONTROLLERS, Scenario
from sma_fmu.runtime.checks import HYSTERESIS_MODES
from sma_fmu.studies.batch.feedforward import BatchFeedforward
from sma_fmu.studies.batch.hardware import BatchLimits, BatchSensors
from sma_fmu.studies.batch.inputs import BatchInputs
from sma_fmu.studies.batch.metrics import MetricsAccumulator
from sma_fmu.studies.batch.plant import BatchPlant
from sma_fmu.studies.batch.pwm import BatchPwm

__all__ = ["BatchUnsupported", "BatchRun", "RECORDS", "unsupported_reason", "run_batch",
           "run_batches", "chunk_steps", "chunk_bounds"]

RECORDS = ("timeseries", "metrics")
CHUNK_ELEMENTS = 65536      # steps x runs per chunk of precomputed signals and errors
# what the engine implements; a field added later is refused until it is added here
_KNOWN_SCENARIO_FIELDS = {"name", "path", "description", "stop_time_s", "step_s", "reference",
                          "load", "controller", "hysteresis_mode", "T_start", "parameter_set",
                          "analysis_window", "group_name", "compensator_parameter_set", "drive",
                          # what `sma-fmu run` records; metrics use every step here as there
                          "output_interval_s", "sensor"}
_KNOWN_CONTROLLER_FIELDS = {"kind", "Kp", "Ki", "alpha", "beta", "model_load", "inverse",
                            "shaping", "power_cap_W",   # shaping: "none" only, checked below
                            "anticipation_s"}           # > 0 only with shaping "reachable"
_KNOWN_DRIVE_FIELDS = {"kind", "frequency_Hz", "peak_W", "I_max_A", "V_max_V"}
_KNOWN_SENSOR_FIELDS = {"noise_ohm_rms", "full_scale_ohm", "bits", "seed"}
_DRIVE_KINDS = ("power", "pwm")   # not runtime.pwm.DRIVE_KINDS: a kind added there is refused


class BatchUnsupported(ValueError):
    """A scenario uses an option the batch engine does not implement; run it on the library path."""


@dataclasses.dataclass
class BatchRun:
    """Outcome of one run of a batch.

    ``data``: the time series (record "timeseries", else None); ``metrics``: the
    :func:`~sma_fmu.cosim.metrics.scenario_metrics` record (None when the run failed);
    ``error``: the failure's message (None when it succeeded); ``path``: "batch", or
    "library" when the run failed in the batch and was run again on the scalar path;
    ``wall_time_s``: the wall time of the whole batch [s] divided by its runs.
    """

    scenario: object
    data: object
    metrics: object
    error: object
    path: str
    wall_time_s: float = None


@functools.lru_cache(maxsize=None)
def _unknown_fields(*types):
    """[fields the engine does not know] of the scenario's, controller's, drive's and sensor's
    classes."""
    return [[f.name for f in dataclasses.fields(kind) if f.name not in known] for kind, known in
            zip(types, (_KNOWN_SCENARIO_FIELDS, _KNOWN_CONTROLLER_FIELDS, _KNOWN_DRIVE_FIELDS,
                        _KNOWN_SENSOR_FIELDS))]


def unsupported_reason(scenario):
    """Why the batch engine cannot run ``scenario`` (a sentence), or None when it can."""
    if not isinstance(scenario, Scenario):
        return f"{scenario!r} is not a Scenario"
    controller, drive, sensor = scenario.controller, scenario.drive, scenario.sensor
    extra, options, drive_options, sensor_options = _unknown_fields(
        type(scenario), type(controller), type(drive), type(sensor))
    if extra:
        return f"scenario option(s) {', '.join(sorted(extra))} are not implemented in the batch engine"
    for name in options:                   # an option added later must be added here
        return (f"{scenario.name}: controller option {name} = "
                f"{getattr(controller, name)!r} is not implemented in the batch engine")
    for name in drive_options:
        return (f"{scenario.name}: drive option {name} = "
                f"{getattr(drive, name)!r} is not implemented in the batch engine")
    for name in sensor_options:
        return (f"{scenario.name}: sensor option {name} = "
                f"{getattr(sensor, name)!r} is not implemented in the batch engine")
    if drive.kind not in _DRIVE_KINDS:
        return f"{scenario.name}: drive kind {drive.kind!r} is not implemented in the batch engine"
    if controller.shaping != "none":
        return (f"{scenario.name}: controller shaping {controller.shaping!r} is not implemented "
                f"in the batch engine")
    if controller.kind not in CONTROLLERS:
        return f"{scenario.name}: controller kind {controller.kind!r} is not implemented"
    if scenario.hysteresis_mode not in HYSTERESIS_MODES:
        return f"{scenario.name}: hysteresis mode {scenario.hysteresis_mode!r} is not implemented"
    return None


def chunk_steps(runs, steps):
    """Steps per chunk: about :data:`CHUNK_ELEMENTS` steps x runs, at least 16, at most n + 1."""
    return max(16, min(steps + 1, CHUNK_ELEMENTS // max(runs, 1)))


def chunk_bounds(steps, rows, change_steps, most_changes=64):
    """[(start, stop)] of chunks of ``rows`` steps; a load step starts a chunk when few are."""
    bounds = set(range(0, steps, rows))
    if len(change_steps) <= most_changes:
        bounds.update(k for k in change_steps if k < steps)
    edges = sorted(bounds) + [steps]
    return list(zip(edges[:-1], edges[1:]))


def _check(scenarios, record):
    if record not in RECORDS:
        raise ValueError(f"record must be one of {', '.join(RECORDS)}, got {record!r}")
    if not scenarios:
        raise ValueError("run_batch needs at least one scenario")
    for scenario in scenarios:
        reason = unsupported_reason(scenario)
        if reason:
            raise BatchUnsupported(reason)


class _Series:
    """Full time series of every run (record "timeseries"): one (n + 1, N) array per column."""

    def __init__(self, inputs):
        shape = (inputs.steps + 1, inputs.size)
        self.columns = {name: np.full(shape, np.nan) for name in
                        ("R", "T", "x", "xi_P", "xi_M", "xi_F", "P_ff", "P_fb", "P", "T_ref")}
        self.saturated = np.zeros(shape, dtype=bool)
        self.inputs = inputs

    def sample(self, k, plant):
        c = self.columns
        c["R"][k], c["T"][k], c["x"][k] = plant.R, plant.temperature, plant.length()
        c["xi_P"][k], c["xi_M"][k], c["xi_F"][k] = plant.xi_P, plant.xi_M, plant.xi_F

    def controls(self, start, feedforward, feedback, power):
        rows = slice(start, start + power.shape[0])
        c = self.columns
        c["P_ff"][rows], c["T_ref"][rows], c["P_fb"][rows], c["P"][rows] = (
            feedforward.P_ff, feedforward.T_ref, feedback, power)
        self.saturated[rows] = feedforward.saturated

    def data(self, run):
        inputs, c = self.inputs, self.columns
        n = inputs.steps
        data = np.zeros(n + 1, dtype=TIMESERIES_DTYPE)
        data["t"] = inputs.times
        one = np.array([run])  # this run's column only (not the whole batch's)
        data["R_ref"] = inputs.references(0, n + 1, one)[:, 0]
        data["load"] = inputs.loads[inputs.segments(0, n + 1, one)[:, 0], run]
        for name, values in c.items():
            data[name] = values[:, run]
        data["stroke"] = c["x"][0, run] - c["x"][:, run]
        data["saturated"] = self.saturated[:, run]
        data["saturated"][n] = False
        return data


def _loop(scenarios, inputs, record):
    """Close the N loops; returns (series or None, metrics accumulator or None, {run: reason})."""
    plant = BatchPlant(inputs, scenarios)
    pwm = (BatchPwm(inputs.pwm_frequency, inputs.pwm_peak, inputs.pwm_runs)
           if inputs.pwm_runs.size else None)
    every_run_pwm = pwm is not None and pwm.runs.size == inputs.size
    sensors, limits = BatchSensors(scenarios, inputs.steps), BatchLimits(scenarios)
    sensed, limited = sensors.runs.size > 0, limits.runs.size > 0
    if limited and pwm is not None:   # where the PWM runs sit among the limited ones
        pwm_position = {run: i for i, run in enumerate(pwm.runs.tolist())}
        limited_pwm = ~limits.linear
        pwm_limited = np.array([pwm_position[run] for run in limits.runs[limited_pwm].tolist()],
                               dtype=int)
    driven_runs = pwm is not None or limited   # the plants get what a driver gives
    times = inputs.times.tolist()             # t_k as run_loop has them (Python floats)
    feedforward = BatchFeedforward(inputs, scenarios)
    size, n, h = inputs.size, inputs.steps, inputs.step_s
    Kp = np.array([s.controller.Kp for s in scenarios])
    Ki = np.array([s.controller.Ki for s in scenarios])
    integral = np.zeros(size)
    series = _Series(inputs) if record == "timeseries" else None
    totals = MetricsAccumulator(inputs, scenarios) if record == "metrics" else None
    stroke = totals is not None and totals.stroke_runs.size > 0   # the accumulator needs x_k
    failed = dict(inputs.failures)
    rows = chunk_steps(size, n)
    work, raw, mask = np.empty(size), np.empty(size), np.empty(size)
    integrate = np.empty(size, dtype=bool)
    zero, step = np.zeros(size), np.full(size, h)
    changes = set(inputs.change_steps)
    subtract, multiply, add, maximum = np.subtract, np.multiply, np.add, np.maximum
    greater_equal, copyto = np.greater_equal, np.copyto
    for start, stop in chunk_bounds(n, rows, inputs.change_steps):
        references = inputs.references(start, stop + 1)
        compensator = feedforward.chunk(start, stop)
        for run, message in compensator.diverged.items():
            failed.setdefault(run, message)
        errors = np.empty((stop - start + 1, size))
        lengths = np.empty((stop - start + 1, size)) if stroke else None   # x_k [m]
        feedback = np.empty((stop - start, size))
        power = np.empty((stop - start + 1, size))      # the PI's output u_k: the demand
        power[-1] = np.nan
        applied = np.empty_like(power) if driven_runs else power   # what the plants get
        applied[-1] = np.nan
        P_ff = compensator.P_ff
        for j in range(stop - start):
            k = start + j
            if k in changes:
                plant.set_segments(inputs.segment_row(k), inputs.segment_row(k - 1))
            if series is not None:
                series.sample(k, plant)
            if stroke:
                lengths[j] = plant.length()
            e, fb, u = errors[j], feedback[j], power[j]
            subtract(plant.R, references[j], e)
            if sensed:                                 # the PI's error: the sensor's reading
                e = subtract(sensors.read(plant.R, k), references[j])
            multiply(Kp, e, fb)                        # PIController.step
            multiply(Ki, integral, work)
            add(fb, work, fb)
            add(P_ff[j], fb, raw)
            maximum(raw, zero, out=u)                  # the clamp; the plant applies u <= 0 as 0
            # held while raw < 0 and e <= 0, i.e. integrate where max(raw, e) >= 0 (at e = 0
            # both add h * 0 = 0)
            maximum(raw, e, out=work)
            greater_equal(work, zero, integrate)
            copyto(mask, integrate)
            multiply(step, e, work)
            multiply(work, mask, work)                 # I + (h e) * 1 = I + h e; * 0 adds 0
            add(integral, work, integral)
            if driven_runs:                            # the drivers between the PI and the plants
                driven = applied[j]
                caps = limits.caps(plant.R) if limited else None
                on_power = None
                if limited and pwm is not None:        # a limited PWM's on-power
                    on_power = pwm.peak.copy()
                    on_power[pwm_limited] = np.minimum(on_power[pwm_limited], caps[limited_pwm])
                if every_run_pwm:
                    copyto(driven, pwm.step(u, times[k], h, on_power))
                else:
                    copyto(driven, u)
                    if pwm is not None:
                        driven[pwm.runs] = pwm.step(u[pwm.runs], times[k], h, on_power)
                    if limited:                        # linear drivers: the demand within it
                        lines = limits.runs[limits.linear]
                        driven[lines] = np.minimum(u[lines], caps[limits.linear])
                u = driven
            plant.step(u)
        np.subtract(plant.R, references[-1], out=errors[-1])   # e_stop, counted by the next chunk
        if stroke:
            lengths[-1] = plant.length()
        if series is not None:
            series.controls(start, compensator, feedback, applied[:-1])
        finite = np.isfinite(power[:-1]).all(axis=0)
        for run in np.flatnonzero(~finite):
            failed.setdefault(int(run), "P_in must be finite")
        if totals is not None:
            last = stop == n
            totals.add(start, errors if last else errors[:-1], applied if last else applied[:-1],
                       compensator.saturated if not last else np.vstack(
                           [compensator.saturated, np.zeros((1, size), dtype=bool)]),
                       None if lengths is None else lengths if last else lengths[:-1])
    if series is not None:
        series.sample(n, plant)
    return series, totals, failed


def run_batch(scenarios, record="metrics"):
    """Run ``scenarios`` (same step and duration) as one batch; returns a list of :class:`BatchRun`.

    ``record``: "metrics" (default; no time series kept) or "timeseries".
    Raises :class:`BatchUnsupported` when a scenario uses an option the engine lacks.
    """
    began = time.perf_counter()
    scenarios = list(scenarios)
    _check(scenarios, record)
    # feedforward runs first, the major inverse before the minor-loop one: the compensators
    # then work on column slices
    order = sorted(range(len(scenarios)), key=lambda i: (
        not scenarios[i].controller.feedforward, scenarios[i].controller.inverse == "minor-loop"))
    ordered = [scenarios[i] for i in order]
    inputs = BatchInputs(ordered)
    with np.errstate(all="ignore"):
        series, totals, failed = _loop(ordered, inputs, record)
    results = [None] * len(scenarios)
    for position, (run, scenario) in enumerate(zip(order, ordered)):
        if position in failed:
            results[run] = _scalar_run(scenario, record)
            continue
        data = series.data(position) if series is not None else None
        metrics = scenario_metrics(data, scenario) if data is not None else totals.metrics(position)
        results[run] = BatchRun(scenario, data, metrics, None, "batch")
    wall = (time.perf_counter() - began) / len(scenarios)
    for result in results:
        result.wall_time_s = wall
    return results


def run_batches(scenarios, record="metrics"):
    """Run ``scenarios`` of any steps and durations: one :func:`run_batch` per (step, steps)
    they share. Returns a :class:`BatchRun` per scenario, in the order given."""
    scenarios = list(scenarios)
    groups = {}
    for index, scenario in enumerate(scenarios):
        groups.setdefault((scenario.step_s, scenario.steps), []).append(index)
    results = [None] * len(scenarios)
    for members in groups.values():
        for index, outcome in zip(members, run_batch([scenarios[i] for i in members], record)):
            results[index] = outcome
    return results


def _scalar_run(scenario, record):
    """A run that failed in the batch, run again on the scalar library path."""
    try:
        result = run_library(scenario)
    except ValueError as error:
        return BatchRun(scenario, None, None, str(error), "library")
    metrics = scenario_metrics(result.data, scenario)
    return BatchRun(scenario, result.data if record == "timeseries" else None, metrics, None,
                    "library")

