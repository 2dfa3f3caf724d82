"""The time column of an isobaric file in seconds, with time stamps repeated at its resolution.

Machines write time in their own unit with a fixed number of decimals: at 0.001 h (3.6 s) a
machine sampling every second repeats each stamp three or four times. Such repeats are
accepted when the stamps that differ step by about the resolution (their median step at most
RESOLUTION_STEPS resolutions; the resolution is the last decimal written). The rows then get
the straight line through the stamps against the row number when every stamp lies within one
resolution of it (a steady sampling rate, so the lag's time step comes out right); otherwise
each stamp goes to the middle of the rows sharing it, with the rows between interpolated. A
note says how many rows repeat, at which resolution, and which of the two was done. A stamp
repeated while the stamps step by far more than the resolution (a duplicated row), or earlier
than the row before, is an error naming the line, the column and the values in the column's
unit.
"""
import numpy as np

from sma_fmu.identification.isobaric.columns import SCALE
from sma_fmu.identification.isobaric.table import plain
from sma_fmu.identification.measurements import MeasurementError

__all__ = ["time_seconds", "resolution", "RESOLUTION_STEPS"]

RESOLUTION_STEPS = 2.0


def resolution(texts, values):
    """The step of the last decimal the cells ``texts`` are written with (in their unit); the
    smallest step between distinct ``values`` where a cell is written with an exponent."""
    decimals = 0
    for text in texts:
        if "e" in text or "E" in text:
            steps = np.diff(np.unique(values))
            return float(steps[steps > 0].min()) if (steps > 0).any() else 0.0
        mark = max(text.rfind("."), text.rfind(","))
        decimals = max(decimals, len(text) - mark - 1 if mark >= 0 else 0)
    return 10.0 ** -decimals


def time_seconds(path, name, unit, values, texts, lines):
    """(time [s], notes) of a time column: ``values`` in its ``unit``, ``texts`` its cells,
    ``lines`` the rows' line numbers."""
    steps = np.diff(values)
    back = np.nonzero(steps < 0)[0]
    if back.size:
        k = int(back[0]) + 1
        raise MeasurementError(f"{path}: line {lines[k]}: {name} = {plain(values[k])} {unit} "
                               f"is earlier than line {lines[k - 1]}'s {plain(values[k - 1])} "
                               f"{unit}; rows must be in time order")
    seconds = values * SCALE[unit]
    repeats = np.nonzero(steps == 0)[0]
    if repeats.size == 0:
        return seconds, []
    k = int(repeats[0]) + 1
    moving = steps[steps > 0]
    if moving.size == 0:
        raise MeasurementError(f"{path}: line {lines[k]}: {name} stays at {plain(values[0])} "
                               f"{unit} on every row; rows must be in time order")
    step, written = float(np.median(moving)), resolution(texts, values)
    if step > RESOLUTION_STEPS * written * (1 + 1e-9):
        raise MeasurementError(f"{path}: line {lines[k]}: {name} = {plain(values[k])} {unit} "
                               f"repeats line {lines[k - 1]}'s, though the time stamps step by "
                               f"{plain(step)} {unit} elsewhere (written to {plain(written)} "
                               f"{unit}): a repeated row? Rows must be in time order")
    spread, how = _spread(values, written, SCALE[unit])
    note = (f"{name}: {repeats.size} of {values.size} rows repeat the time stamp before them "
            f"(written to {plain(written)} {unit} = {plain(written * SCALE[unit])} s); {how}")
    return spread * SCALE[unit], [note]


def _spread(values, written, scale):
    """(times in the column's unit, how): the straight line through the stamps against the
    row when every stamp lies within one resolution ``written`` of it (a machine sampling at
    a steady rate), else the stamps at the middle row of each run of equal stamps,
    interpolated linearly between them. ``scale``: seconds per unit, for the note."""
    rows = np.arange(values.size, dtype=float)
    slope, intercept = np.polyfit(rows, values, 1)
    line = intercept + slope * rows
    if np.max(np.abs(values - line)) <= written * (1 + 1e-9):
        return line, f"the rows are evenly spaced, {plain(slope * scale)} s apart (the line " \
                     f"through the stamps; every stamp lies within its resolution of it)"
    first = np.nonzero(np.concatenate([[True], np.diff(values) > 0]))[0]
    middle = (first + np.append(first[1:], values.size) - 1) / 2.0
    stamps = values[first]
    rate = (stamps[-1] - stamps[0]) / (middle[-1] - middle[0])
    inside = np.interp(rows, middle, stamps)
    times = np.where(rows < middle[0], stamps[0] + (rows - middle[0]) * rate,
                     np.where(rows > middle[-1], stamps[-1] + (rows - middle[-1]) * rate, inside))
    return times, "the sampling is uneven, so each stamp is put at the middle row of the rows " \
                  "sharing it and the rows between are interpolated"
