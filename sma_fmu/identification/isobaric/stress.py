"""The stress column of an isobaric file: its load ramp, its limit and its spread.

- Load ramp: a machine export often starts before the load is on (the stress rising from
  zero while the temperature waits) and may end after it is off. When the running median of
  the stress (over RAMP_WINDOW rows) starts more than STRESS_SPREAD from the file's median
  stress, the rows up to the first whose running median comes within RAMP_BAND of it (or
  three standard deviations of its noise, if more) are the ramp; the same at the end is the
  unloading. Both are left out of every column, and a note names their lines and stresses.
- Limit: the file's stress (the median of the rows kept) must lie in (0, MAX_STRESS_MPA], the
  limit ``--stress`` has; a value above it names the first row over it.
- Spread: the fit needs one load per file. A stress whose medians over ten consecutive blocks
  of rows span more than STRESS_SPREAD of the file's median is an error.
"""
import numpy as np
from scipy import ndimage

from sma_fmu.identification.isobaric.columns import SCALE
from sma_fmu.identification.isobaric.table import plain
from sma_fmu.identification.limits import MAX_STRESS_MPA
from sma_fmu.identification.measurements import MeasurementError

__all__ = ["constant_load_rows", "file_stress", "STRESS_SPREAD", "RAMP_WINDOW"]

STRESS_SPREAD = 0.10
RAMP_WINDOW = 11       # rows of the running median that finds a load ramp
RAMP_BAND = 0.01       # the ramp ends within this share of the median stress (or 3 noise sigma)


def constant_load_rows(name, values, lines, unit="MPa"):
    """(slice of the rows at constant load, notes): the load ramp before them and the
    unloading after them left out. ``values`` in MPa, ``lines`` the rows' line numbers,
    ``unit`` the column's own (the notes quote its values in it)."""
    n = values.size
    plateau = float(np.median(values))
    if not plateau > 0 or n < 2:
        return slice(0, n), []
    smooth = ndimage.median_filter(values, size=min(RAMP_WINDOW, n), mode="nearest")
    distance = np.abs(smooth - plateau)
    if not max(distance[0], distance[-1]) > STRESS_SPREAD * plateau:
        return slice(0, n), []
    near = np.abs(values - plateau) <= STRESS_SPREAD / 2 * plateau
    band = max(RAMP_BAND * plateau, 3.0 * 1.4826 * float(np.median(np.abs(values[near]
                                                                            - plateau))))
    inside = np.nonzero(distance <= band)[0]
    if inside.size == 0:
        return slice(0, n), []
    start = int(inside[0]) if distance[0] > STRESS_SPREAD * plateau else 0
    stop = int(inside[-1]) + 1 if distance[-1] > STRESS_SPREAD * plateau else n
    scale = SCALE[unit]
    notes = []
    for rows, what in ((slice(0, start), "load ramp before the constant load"),
                       (slice(stop, n), "unloading after the constant load")):
        part = values[rows]
        if part.size:
            notes.append(f"{what}: lines {lines[rows.start]}-{lines[rows.stop - 1]} "
                         f"({part.size} rows, {name} {plain(part[0] / scale)} -> "
                         f"{plain(part[-1] / scale)} {unit}) left out; the constant load "
                         f"(median {plain(np.median(values[start:stop]) / scale)} {unit}) runs "
                         f"over lines {lines[start]}-{lines[stop - 1]}")
    return slice(start, stop), notes


def _problem(name, values, lines, unit, median):
    """Why a column's median stress [MPa] cannot be the file's load, or ""."""
    if not median > 0:
        return f"column {name}: median stress {plain(median / SCALE[unit])} {unit} must be > 0"
    if median <= MAX_STRESS_MPA:
        return ""
    row = int(np.argmax(values > MAX_STRESS_MPA))
    shown = f"{plain(values[row] / SCALE[unit])} {unit}" + \
        ("" if unit == "MPa" else f" = {plain(values[row])} MPa")
    return (f"line {lines[row]}: {name} = {shown}: the file's stress (median {plain(median)} "
            f"MPa) is above {MAX_STRESS_MPA:g} MPa, the most --stress accepts (beyond any Ti-Ni "
            f"wire's breaking stress); is the column in {unit}?")


def file_stress(path, name, values, lines, unit="MPa", given=None):
    """(median stress [MPa], notes) of a stress column, ``values`` in MPa, ``lines`` the rows'
    line numbers. Raises when the stress moves more than STRESS_SPREAD, and, unless the caller
    gives the stress (``given`` [MPa], from --load or --stress), when the median is outside
    (0, MAX_STRESS_MPA]; with one given, that and a median more than STRESS_SPREAD from it
    are notes."""
    median = float(np.median(values))
    problem = _problem(name, values, lines, unit, median)
    if problem and given is None:
        raise MeasurementError(f"{path}: {problem}")
    if median > 0:
        blocks = [float(np.median(part)) for part in np.array_split(values, 10) if part.size]
        spread = (max(blocks) - min(blocks)) / median
        if spread > STRESS_SPREAD:
            raise MeasurementError(
                f"{path}: column {name}: the stress moves from {min(blocks):.4g} to "
                f"{max(blocks):.4g} MPa inside the file ({100 * spread:.0f} % of its median "
                f"{median:.4g} MPa; at most {100 * STRESS_SPREAD:.0f} %): the fit needs one "
                f"load per file")
    if given is None:
        return median, []
    if problem:
        return median, [f"{problem} Not used: the stress is given ({plain(given)} MPa)"]
    if given > 0 and abs(median - given) > STRESS_SPREAD * given:
        return median, [f"column {name}: median {plain(median)} MPa, {plain(given)} MPa given "
                        f"({100 * (median / given - 1):+.0f} %); the given one is used"]
    return median, []
