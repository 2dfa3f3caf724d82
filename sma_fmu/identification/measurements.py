"""Measurement files for identification (CSV), read and checked row by row.

Constant-load sweeps (paper Figs. 4-5): columns ``temperature_C, load_kg, resistance_ohm``
and optionally ``direction`` (heating|cooling). Without it the direction is inferred from
the temperature sequence within each run of equal load: a rising temperature means
heating, a falling one cooling, an equal one keeps the last (the first row takes the
direction of the first change).

Constant-temperature load cycles (paper Fig. 6): columns ``load_kg, resistance_ohm,
temperature_C`` in measurement order; one file is one experiment at one temperature.

Other columns are ignored. Every problem raises :class:`MeasurementError` naming the file,
the line (1 = header) and what is wrong.
"""
import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sma_fmu.runtime.constants import COOLING, HEATING

__all__ = ["MeasurementError", "ConstantLoadData", "ConstantTemperatureData",
           "read_constant_load", "read_constant_temperature", "TEMPERATURE_SPREAD_LIMIT_K"]

TEMPERATURE_SPREAD_LIMIT_K = 2.0  # a constant-temperature file may scatter this much
_DIRECTIONS = {"heating": HEATING, "cooling": COOLING}


class MeasurementError(ValueError):
    """A measurement file is malformed; the message names the file, line and problem."""


@dataclass
class ConstantLoadData:
    """Rows of one or more constant-load files: arrays of equal length."""

    temperature: np.ndarray   # degC
    load: np.ndarray          # kg
    resistance: np.ndarray    # ohm
    direction: np.ndarray     # +1 heating, -1 cooling
    source: np.ndarray        # index into ``files``
    files: list


@dataclass
class ConstantTemperatureData:
    """One constant-temperature experiment: loads and resistances in measurement order."""

    path: Path
    temperature: float        # mean measured temperature [degC]
    load: np.ndarray          # kg
    resistance: np.ndarray    # ohm


def _rows(path, required):
    path = Path(path)
    if path.is_dir():
        raise MeasurementError(f"{path}: is a folder, not a CSV file")
    number = 1
    try:
        # utf-8-sig: a byte-order mark (as spreadsheet programs write) is not part of the header
        with open(path, newline="", encoding="utf-8-sig") as stream:
            reader = csv.reader(stream)
            header = next(reader, None)
            if header is None:
                raise MeasurementError(f"{path}: line 1: the file is empty; expected a header with "
                                       f"{', '.join(required)}")
            header = [name.strip() for name in header]
            missing = [name for name in required if name not in header]
            if missing:
                raise MeasurementError(f"{path}: line 1: missing column(s) {', '.join(missing)}; "
                                       f"found {', '.join(header)}")
            columns = {name: header.index(name) for name in header}
            rows = []
            for number, row in enumerate(reader, start=2):
                if any(cell.strip() for cell in row):
                    rows.append((number, row))
    except FileNotFoundError:
        raise MeasurementError(f"{path}: file not found") from None
    except UnicodeDecodeError as error:
        raise MeasurementError(f"{path}: not a UTF-8 text file (byte {error.start}: {error.reason}); "
                               f"save it as UTF-8 CSV") from None
    except csv.Error as error:
        raise MeasurementError(f"{path}: line {number + 1}: not readable as CSV: {error}") from None
    except OSError as error:
        raise MeasurementError(f"{path}: cannot read the file: {error.strerror or error}") from None
    if not rows:
        raise MeasurementError(f"{path}: no data rows after the header")
    return path, columns, rows


def _cell(path, number, row, columns, name):
    index = columns[name]
    text = row[index].strip() if index < len(row) else ""
    if not text:
        raise MeasurementError(f"{path}: line {number}: column {name} is empty")
    return text


def _number(path, number, row, columns, name, nonnegative=False):
    text = _cell(path, number, row, columns, name)
    try:
        value = float(text)
    except ValueError:
        raise MeasurementError(f"{path}: line {number}: {name} = {text!r} is not a number") from None
    if not math.isfinite(value):
        raise MeasurementError(f"{path}: line {number}: {name} = {text!r} is not finite")
    if nonnegative and value < 0:
        raise MeasurementError(f"{path}: line {number}: {name} = {value!r} must be >= 0")
    return value


def _infer_directions(temperatures, loads):
    """Direction per row from the temperature sequence within runs of equal load."""
    directions = np.zeros(len(temperatures), dtype=int)
    start = 0
    for end in range(1, len(temperatures) + 1):
        if end == len(temperatures) or loads[end] != loads[start]:
            run = temperatures[start:end]
            steps = np.sign(np.diff(run))
            first = next((int(s) for s in steps if s != 0), HEATING)
            current = first
            directions[start] = first
            for i, s in enumerate(steps, start=start + 1):
                current = int(s) if s != 0 else current
                directions[i] = current
            start = end
    return directions


def read_constant_load(paths):
    """Read constant-load CSV files into one :class:`ConstantLoadData`."""
    parts = {key: [] for key in ("temperature", "load", "resistance", "direction", "source")}
    files = []
    for source, path in enumerate(paths):
        path, columns, rows = _rows(path, ("temperature_C", "load_kg", "resistance_ohm"))
        files.append(path)
        temperature = [_number(path, n, r, columns, "temperature_C") for n, r in rows]
        load = [_number(path, n, r, columns, "load_kg", nonnegative=True) for n, r in rows]
        resistance = [_number(path, n, r, columns, "resistance_ohm") for n, r in rows]
        for (number, _), value in zip(rows, resistance):
            if value <= 0:
                raise MeasurementError(f"{path}: line {number}: resistance_ohm = {value!r} must be > 0")
        if "direction" in columns:
            direction = []
            for number, row in rows:
                text = _cell(path, number, row, columns, "direction").lower()
                if text not in _DIRECTIONS:
                    raise MeasurementError(f"{path}: line {number}: direction = {text!r}; "
                                           f"expected heating or cooling")
                direction.append(_DIRECTIONS[text])
        else:
            direction = list(_infer_directions(np.array(temperature), load))
        if len(set(temperature)) == 1:
            raise MeasurementError(f"{path}: only one temperature ({temperature[0]!r} degC): a "
                                   f"constant-load sweep needs temperatures across the transformation")
        for key, values in (("temperature", temperature), ("load", load), ("resistance", resistance),
                            ("direction", direction), ("source", [source] * len(rows))):
            parts[key].extend(values)
    return ConstantLoadData(np.array(parts["temperature"]), np.array(parts["load"]),
                            np.array(parts["resistance"]), np.array(parts["direction"], dtype=int),
                            np.array(parts["source"], dtype=int), files)


def read_constant_temperature(path):
    """Read one constant-temperature CSV file as a :class:`ConstantTemperatureData`."""
    path, columns, rows = _rows(path, ("load_kg", "resistance_ohm", "temperature_C"))
    load = np.array([_number(path, n, r, columns, "load_kg", nonnegative=True) for n, r in rows])
    resistance = np.array([_number(path, n, r, columns, "resistance_ohm") for n, r in rows])
    temperature = np.array([_number(path, n, r, columns, "temperature_C") for n, r in rows])
    for (number, _), value in zip(rows, resistance):
        if value <= 0:
            raise MeasurementError(f"{path}: line {number}: resistance_ohm = {value!r} must be > 0")
    spread = float(temperature.max() - temperature.min())
    if spread > TEMPERATURE_SPREAD_LIMIT_K:
        worst = rows[int(np.argmax(np.abs(temperature - np.median(temperature))))][0]
        raise MeasurementError(f"{path}: line {worst}: temperature_C spreads over {spread:.3g} K; "
                               f"a constant-temperature file may vary by at most "
                               f"{TEMPERATURE_SPREAD_LIMIT_K} K")
    if len(set(load.tolist())) == 1:
        raise MeasurementError(f"{path}: only one load ({load[0]!r} kg): a constant-temperature "
                               f"experiment needs the load to change")
    return ConstantTemperatureData(path, float(temperature.mean()), load, resistance)
