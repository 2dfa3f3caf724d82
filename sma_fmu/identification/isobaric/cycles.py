"""Split an isobaric temperature record into heating and cooling branches, at any cycle count.

How the cycles are found (the reader states it in the report, :func:`splitting_note`):

1. The temperature's dominant period P [samples] is the peak of its periodogram (scipy's
   ``signal.periodogram``, linear trend removed, the zero frequency left out). A file of two
   cycles and one of a thousand are treated alike: the scales below follow P, not the row count.
2. The temperature is smoothed by a Savitzky-Golay filter (order 2) over P/6 samples, which
   keeps the turning points of a cycle of P samples and averages thermocouple noise.
3. Turning points are the maxima and minima of the smoothed signal with a prominence of at
   least half its range, at least P/2 apart (scipy's ``find_peaks``); a branch runs from one
   turning point to the next, its direction the sign of the smoothed change over it. A
   branch is complete when it swings through 70 % of the median branch's swing (of the
   whole range with two branches or fewer).

``select_cycles`` keeps a range of cycles (``--cycles 5:``): labs drop the first, unstabilised
cycles. Cycle numbers stay those of the file; residual-strain levels restart at 0.
"""
import math
import re
from dataclasses import dataclass, replace

import numpy as np
from scipy import signal

from sma_fmu.identification.measurements import MeasurementError
from sma_fmu.runtime.constants import COOLING, HEATING

__all__ = ["Branch", "Splitting", "dominant_period", "smooth", "split_branches", "parse_cycles",
           "select_cycles", "splitting_note", "MIN_TEMPERATURE_SPAN_K", "COMPLETE_SHARE"]

MIN_TEMPERATURE_SPAN_K = 10.0     # the smoothed temperature must move this much
COMPLETE_SHARE = 0.7              # a branch swinging 70 % of a typical branch is complete
SMOOTHING_PER_PERIOD = 6          # Savitzky-Golay window = period / this


@dataclass
class Branch:
    """Rows ``start`` .. ``stop - 1`` of one heating or cooling branch."""

    start: int
    stop: int
    direction: int        # +1 heating, -1 cooling
    cycle: int            # heating branches count cycles from 1; a leading cooling is cycle 0
    level: int            # residual-strain level: heating uses it, cooling goes level -> level+1
    complete: bool        # covers most of the temperature range


@dataclass
class Splitting:
    """How the branches were found: period and window [samples], turning points."""

    period_samples: float
    window_samples: int
    turning_points: int
    cycles_in_file: int
    selected: str = "all"


def smooth(values, window):
    """Savitzky-Golay smoothing (order 2) over ``window`` samples (made odd, at most the length)."""
    values = np.asarray(values, dtype=float)
    window = min(int(window) | 1, values.size if values.size % 2 else values.size - 1)
    if window < 5:
        return values.copy()
    return signal.savgol_filter(values, window, 2, mode="interp")


def dominant_period(values):
    """Period [samples] of the strongest oscillation of ``values`` (periodogram peak)."""
    values = np.asarray(values, dtype=float)
    frequency, power = signal.periodogram(values, detrend="linear")
    if frequency.size < 3:
        return float(values.size)
    peak = 1 + int(np.argmax(power[1:]))
    return float(1.0 / frequency[peak])


def split_branches(temperature, path="<data>"):
    """([Branch], smoothed temperature [degC], Splitting) of a measured temperature record."""
    temperature = np.asarray(temperature, dtype=float)
    period = min(dominant_period(temperature), float(temperature.size))
    window = max(5, int(period // SMOOTHING_PER_PERIOD))
    smoothed = smooth(temperature, window)
    span = float(np.ptp(smoothed))
    if span < MIN_TEMPERATURE_SPAN_K:
        raise MeasurementError(f"{path}: the temperature does not vary: its smoothed signal spans "
                               f"{span:.3g} K (at least {MIN_TEMPERATURE_SPAN_K:g} K needed for "
                               f"thermal cycling)")
    distance = max(1, int(period // 2))
    peaks, _ = signal.find_peaks(smoothed, prominence=0.5 * span, distance=distance)
    troughs, _ = signal.find_peaks(-smoothed, prominence=0.5 * span, distance=distance)
    turning = sorted(set(peaks.tolist()) | set(troughs.tolist()))
    bounds = [0] + [t for t in turning if 0 < t < smoothed.size - 1] + [smoothed.size]
    branches, cycle, level = [], 0, 0
    changes = [float(smoothed[stop - 1] - smoothed[start]) for start, stop in zip(bounds, bounds[1:])]
    # complete: most of a typical branch's swing (noise spikes widen the full range)
    typical = min(span, float(np.median(np.abs(changes)))) if len(changes) > 2 else span
    for (start, stop), change in zip(zip(bounds, bounds[1:]), changes):
        direction = HEATING if change >= 0 else COOLING
        if direction == HEATING:
            cycle += 1
        branches.append(Branch(start, stop, direction, cycle, level,
                               abs(change) >= COMPLETE_SHARE * typical))
        if direction == COOLING:
            level += 1
    directions = {b.direction for b in branches if b.complete}
    if directions != {HEATING, COOLING}:
        only = "heating" if HEATING in directions else "cooling"
        raise MeasurementError(f"{path}: a single branch: the temperature only goes one way "
                               f"({only}, {smoothed[0]:.4g} -> {smoothed[-1]:.4g} degC smoothed); "
                               f"isobaric cycling needs at least one heating and one cooling branch")
    cycles = len({b.cycle for b in branches if b.complete and b.direction == HEATING})
    return branches, smoothed, Splitting(period, window, len(bounds) - 2, cycles)


def parse_cycles(text):
    """(first, last) cycle numbers of ``A:B``, ``A:``, ``:B`` or ``A`` (1-based, inclusive;
    None = open end); raises ValueError naming the text."""
    match = re.fullmatch(r"\s*(\d*)\s*(:?)\s*(\d*)\s*", str(text))
    if not match or not (match.group(1) or match.group(3)) or \
            (not match.group(2) and not match.group(1)):
        raise ValueError(f"--cycles {text!r}: expected A:B, A:, :B or A (cycle numbers from 1)")
    first = int(match.group(1)) if match.group(1) else None
    last = int(match.group(3)) if match.group(3) else None
    if not match.group(2):
        last = first
    if (first is not None and first < 1) or (last is not None and last < 1) or \
            (first is not None and last is not None and last < first):
        raise ValueError(f"--cycles {text!r}: cycle numbers start at 1 and the range must not "
                         f"be empty")
    return first, last


def select_cycles(branches, selection, path="<data>"):
    """(rows slice, branches rebased to it) keeping the cycles ``selection`` = (first, last)."""
    first, last = selection
    cycles = sorted({b.cycle for b in branches if b.direction == HEATING})
    low = first if first is not None else 0
    high = last if last is not None else math.inf
    kept = [b for b in branches if low <= b.cycle <= high]
    if not any(b.complete and b.direction == HEATING for b in kept) or \
            not any(b.complete and b.direction == COOLING for b in kept):
        raise MeasurementError(
            f"{path}: --cycles {first or ''}:{last or ''} keeps no complete heating and cooling "
            f"branch; the file has cycles {cycles[0] if cycles else 0} to "
            f"{cycles[-1] if cycles else 0}")
    start, stop = kept[0].start, kept[-1].stop
    level0 = kept[0].level
    rebased = [replace(b, start=b.start - start, stop=b.stop - start, level=b.level - level0)
               for b in kept]
    return slice(start, stop), rebased


def splitting_note(split, branches, time_column):
    """One sentence: how the cycles of a file were found."""
    unit = "samples" if not time_column else "samples (rows)"
    complete = sum(1 for b in branches if b.complete)
    return (f"dominant period of the temperature {split.period_samples:.1f} {unit} "
            f"(periodogram peak); Savitzky-Golay smoothing over {split.window_samples} samples; "
            f"{split.turning_points} turning points (prominence >= half the range, >= half a "
            f"period apart); {split.cycles_in_file} cycles in the file, cycles {split.selected} "
            f"used: {len(branches)} branches, {complete} complete")
