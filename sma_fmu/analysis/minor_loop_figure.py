"""Minor loops on the resistance-temperature plane: the runtime plant swept through a history.

:func:`trace_history` drives the real :class:`~sma_fmu.runtime.plant.PlantStepper` (mode
"continuous", spec section 6) through a list of temperature turning points at one load. The
sweep is quasi-static: each step holds its power for :data:`HOLD_TIME_CONSTANTS` thermal time
constants, with the power that lands the thermal model of section 9 on the next temperature
(:func:`~sma_fmu.runtime.thermal.power_to_reach`). The section 6 hysteresis depends on the temperature path only, not
on its speed, so the curve is the one any slow enough sweep gives. Each segment is cut into
equal steps of at most ``step_K`` and also lands on every earlier turning point it passes,
so the sample where a minor loop closes is a row of the trace.

:func:`write_loops` writes ``loops.csv`` (T_degC, R_ohm, direction, stack_depth) and
``loops.png`` (the trace over the major heating and cooling branches, reversal points
numbered, closed loops ringed). Drawn on :class:`matplotlib.figure.Figure` objects: no pyplot.
"""
import bisect
import math
from collections import namedtuple
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from sma_fmu.files.output_folder import staged_folder
from sma_fmu.runtime.checks import direction_name
from sma_fmu.runtime.constant_load import (branch_constants, constant_load_resistance,
                                           require_temperature)
from sma_fmu.runtime.constants import COOLING, HEATING
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.thermal import power_to_reach, step_decay

__all__ = ["HOLD_TIME_CONSTANTS", "MAX_STEPS", "MIN_STEP_K", "LoopTrace",
           "check_load", "check_history", "check_step", "trace_history", "reversal_rows",
           "closure_rows", "loops_csv", "loops_figure", "write_loops"]

HOLD_TIME_CONSTANTS = 20.0   # each step holds its power for 20 tau_th: the wire settles
MAX_STEPS = 1_000_000        # a longer sweep is refused (memory, time)
MIN_STEP_K = 1e-6            # K: finer steps would approach the rounding of the landing power

LoopTrace = namedtuple("LoopTrace", ["T", "R", "direction", "depth", "history", "load"])
LoopTrace.__doc__ = """The plant's path through a temperature history, one row per sample.

T : temperature [degC]; R : resistance [ohm]; direction : +1 heating, -1 cooling (int);
depth : points on the reversal stack after the sample (int); the first row is the start.
history : the turning points [degC]; load : the load [kg].
"""


def _degC(value):
    return f"{value:.15g}"


def check_load(load, params):
    """Raise ``ValueError`` unless ``load`` [kg] is >= 0 and inside the model's range: the
    branch constants exist and both hysteresis centres lie at or below ``validity.T_max``."""
    if not (isinstance(load, (int, float)) and math.isfinite(load) and load >= 0.0):
        raise ValueError(f"the load must be a finite number >= 0 kg, got {load!r}")
    for direction in (HEATING, COOLING):
        centre = branch_constants(load, direction, params).centre
        if centre > params.T_max:
            raise ValueError(
                f"at {load:g} kg the {direction_name(direction)} transformation is centred at "
                f"{_degC(centre)} degC, above validity.T_max = {_degC(params.T_max)} degC: "
                "beyond the model's range")


def check_history(history, params):
    """The turning points ``history`` [degC] as floats; raise ``ValueError`` naming the bad one.

    At least two points, neighbours different, none above ``validity.T_max``; the wire is
    heated by its current and cools passively, so the first point must be at or above
    ``thermal.T_room`` and every later one above it.
    """
    points = [require_temperature(f"point {i + 1}", value) for i, value in enumerate(history)]
    if len(points) < 2:
        raise ValueError(f"needs at least two turning points, got {len(points)}")
    room = params.T_room
    for index, value in enumerate(points, 1):
        if value > params.T_max:
            raise ValueError(f"point {index} = {_degC(value)} degC is above validity.T_max = "
                             f"{_degC(params.T_max)} degC, outside the model's range")
        if value < room or (index > 1 and value == room):
            raise ValueError(f"point {index} = {_degC(value)} degC is not above thermal.T_room = "
                             f"{_degC(room)} degC: the wire cools only passively, towards T_room")
        if index > 1 and value == points[index - 2]:
            raise ValueError(f"point {index} = {_degC(value)} degC repeats the point before it")
    return points


def check_step(history, step_K):
    """Raise ``ValueError`` unless ``step_K`` [K] is at least :data:`MIN_STEP_K` and sweeps
    ``history`` [degC] in at most :data:`MAX_STEPS` steps."""
    if not (isinstance(step_K, (int, float)) and math.isfinite(step_K) and step_K >= MIN_STEP_K):
        raise ValueError(f"the step must be a finite number >= {MIN_STEP_K:g} K, got {step_K!r}")
    span = sum(abs(b - a) for a, b in zip(history, history[1:]))
    if span / step_K > MAX_STEPS:
        raise ValueError(f"{span:g} K of history in steps of {step_K:g} K is more than "
                         f"{MAX_STEPS:,} steps; take a larger step")


def _targets(start, end, step_K, earlier):
    """Temperatures [degC] of the steps from ``start`` to ``end``, in path order: equal steps of
    at most ``step_K`` [K] and the ``earlier`` turning points strictly between; a step point
    within ``step_K``/1000 of a turning point (or two such points) is merged into one."""
    tolerance = 1e-3 * step_K
    low, high = min(start, end), max(start, end)
    marks = []
    for point in sorted(p for p in earlier if low + tolerance < p < high - tolerance):
        if not marks or point - marks[-1] > tolerance:
            marks.append(point)
    targets = list(marks)
    count = max(1, math.ceil((high - low) / step_K))
    for k in range(1, count):
        value = start + (end - start) * k / count
        i = bisect.bisect_left(marks, value)
        if all(abs(value - marks[j]) > tolerance for j in (i - 1, i) if 0 <= j < len(marks)):
            targets.append(value)
    targets.sort(reverse=end < start)
    return targets + [end]


def trace_history(params, load, history, step_K=0.1):
    """Sweep the plant (mode "continuous") through ``history`` [degC] at ``load`` [kg].

    ``step_K`` [K] is the largest temperature step. The wire starts at the first point on
    the major heating branch with an empty memory, as :class:`PlantStepper` does. Returns a
    :class:`LoopTrace`. Bad arguments raise ``ValueError`` before anything is computed.
    """
    check_load(load, params)
    points = check_history(history, params)
    check_step(points, step_K)
    hold = HOLD_TIME_CONSTANTS * params.tau_th
    decay = step_decay(hold, params.tau_th)
    plant = PlantStepper(params, T_start=points[0], mode="continuous", load=load)
    rows = [(plant.outputs.T, plant.outputs.R, plant.direction, 0)]
    for index in range(1, len(points)):
        for target in _targets(points[index - 1], points[index], step_K, points[:index - 1]):
            power = power_to_reach(plant.temperature, target, params.T_room, params.K_th, decay)
            if power < 0.0:
                raise ValueError(
                    f"point {index + 1} = {_degC(points[index])} degC cannot be reached: passive "
                    f"cooling stops at thermal.T_room = {_degC(params.T_room)} degC")
            out = plant.step(power, load, hold)
            rows.append((out.T, out.R, plant.direction, len(plant.reversals)))
    T, R, direction, depth = zip(*rows)
    return LoopTrace(np.array(T), np.array(R), np.array(direction, dtype=int),
                     np.array(depth, dtype=int), tuple(points), float(load))


def reversal_rows(trace):
    """Row indices of the reversal points of a :class:`LoopTrace`: the samples before a change
    of direction (the start counts: the plant starts heating)."""
    return np.nonzero(trace.direction[:-1] != trace.direction[1:])[0]


def closure_rows(trace):
    """Row indices of a :class:`LoopTrace` where a closed loop was wiped out (the stack shrank)."""
    return np.nonzero(np.diff(trace.depth) < 0)[0] + 1


def loops_csv(trace):
    """The trace as CSV text: T_degC, R_ohm, direction (heating|cooling), stack_depth."""
    lines = ["T_degC,R_ohm,direction,stack_depth"]
    for T, R, d, depth in zip(trace.T, trace.R, trace.direction, trace.depth):
        lines.append(f"{float(T)!r},{float(R)!r},{direction_name(int(d))},{int(depth)}")
    return "\n".join(lines) + "\n"


def _draw(axis, trace, params, T_low, T_high, labels):
    margin = 0.03 * (T_high - T_low)
    grid = np.linspace(max(T_low - margin, -273.0), T_high + margin, 600)
    for direction, colour, name in ((HEATING, "tab:red", "heating"),
                                    (COOLING, "tab:blue", "cooling")):
        major = [constant_load_resistance(t, trace.load, direction, params) for t in grid]
        axis.plot(grid, major, color=colour, lw=4.0, alpha=0.25,
                  label=f"major {name} branch" if labels else None)
    cuts = np.concatenate([[0], reversal_rows(trace), [trace.T.size - 1]])
    for first, last in zip(cuts[:-1], cuts[1:]):
        heating = trace.direction[last] == HEATING
        axis.plot(trace.T[first:last + 1], trace.R[first:last + 1], lw=1.3,
                  color="darkred" if heating else "navy")
        middle = (first + last) // 2
        if last - first >= 4:
            axis.annotate("", xy=(trace.T[middle + 1], trace.R[middle + 1]),
                          xytext=(trace.T[middle], trace.R[middle]),
                          arrowprops=dict(arrowstyle="-|>", color="0.2", lw=0.8, mutation_scale=12))
    if labels:
        axis.plot([], [], color="darkred", lw=1.3, label="plant, heating")
        axis.plot([], [], color="navy", lw=1.3, label="plant, cooling")
    reversals, closures = reversal_rows(trace), closure_rows(trace)
    axis.plot(trace.T[reversals], trace.R[reversals], "o", ms=5, color="black",
              label="reversal point (numbered)" if labels else None)
    axis.plot(trace.T[closures], trace.R[closures], "o", ms=13, mfc="none", mec="tab:green",
              mew=1.6, label="loop closed here and wiped out" if labels else None)
    for number, row in enumerate(reversals, 1):
        if T_low <= trace.T[row] <= T_high:
            axis.annotate(str(number), (trace.T[row], trace.R[row]), xytext=(4, 4),
                          textcoords="offset points", fontsize=8)
    axis.set_xlim(grid[0], grid[-1])
    axis.set(xlabel="temperature T [degC]", ylabel="resistance R [ohm]")
    axis.grid(alpha=0.3)


def loops_figure(trace, params):
    """A :class:`~matplotlib.figure.Figure`: the whole history, and an enlargement of the
    turning points inside it (those between the lowest and the highest) when there are two."""
    low, high = min(trace.history), max(trace.history)
    inner = sorted({t for t in trace.history if low < t < high})
    figure = Figure(figsize=(12 if len(inner) >= 2 else 7, 5.2))
    axes = figure.subplots(1, 2 if len(inner) >= 2 else 1, squeeze=False)[0]
    _draw(axes[0], trace, params, low, high, labels=True)
    axes[0].legend(fontsize=8, loc="center right")
    path = " -> ".join(f"{t:g}" for t in trace.history)
    axes[0].set_title(f"load {trace.load:g} kg, history {path} degC", fontsize=9)
    if len(inner) >= 2:
        pad = max(1.0, 0.15 * (inner[-1] - inner[0]))
        zoom_low, zoom_high = math.floor(inner[0] - pad), math.ceil(inner[-1] + pad)
        _draw(axes[1], trace, params, zoom_low, zoom_high, labels=False)
        shown = (trace.T >= zoom_low) & (trace.T <= zoom_high)
        r_low, r_high = trace.R[shown].min(), trace.R[shown].max()
        margin = 0.05 * (r_high - r_low) + 1e-3
        axes[1].set_ylim(r_low - margin, r_high + margin)
        axes[1].set_title(f"enlarged: {zoom_low:g} to {zoom_high:g} degC", fontsize=9)
        axes[0].axvspan(zoom_low, zoom_high, color="0.5", alpha=0.08, lw=0)
    figure.suptitle("Minor loops with return-point memory (mode \"continuous\"): every loop "
                    "closes where it began", fontsize=10)
    figure.tight_layout()
    return figure


def write_loops(trace, params, out_dir):
    """Write ``loops.csv`` and ``loops.png`` into ``out_dir`` (all or nothing); return the paths."""
    figure = loops_figure(trace, params)
    with staged_folder(out_dir) as stage:
        (stage / "loops.csv").write_text(loops_csv(trace), encoding="utf-8")
        figure.savefig(stage / "loops.png", dpi=110)
    return [Path(out_dir) / "loops.csv", Path(out_dir) / "loops.png"]
