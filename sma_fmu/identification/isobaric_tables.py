"""Per-cycle transformation temperatures, actuation, hysteresis and residual strain: data vs model.

The same tangent construction (:mod:`sma_fmu.identification.transformation_temperatures`)
runs on the data (each branch's smoothed temperature against its measured strain) and on
the fitted model (each branch's model curve, with that cycle's residual-strain offsets, on
a 2,000-point grid over the branch's temperature range), so the two columns differ only by
the fit, not by the method. Written as CSV (one row per file, cycle and quantity) and as
Markdown (one table per file).
"""
import csv
import io
import math

import numpy as np

from sma_fmu.identification.isobaric_model import branch_levels, branch_share
from sma_fmu.identification.transformation_temperatures import (QUANTITIES, branch_tangents,
                                                                cycle_numbers)
from sma_fmu.runtime.constants import COOLING, HEATING

__all__ = ["model_branch_strain", "cycle_rows", "rows_csv", "rows_markdown"]

GRID_POINTS = 2000


def model_branch_strain(temperature, branch, data, params, offsets, per_cycle=True):
    """Model strain [1] of one branch at ``temperature`` [degC], with its offsets [1]."""
    levels = branch_levels(data.load, branch.direction, params, data.reference_length)
    q = branch_share(temperature, levels.constants)
    level = branch.level if per_cycle else 0
    offset = offsets[min(level, len(offsets) - 1)]
    if branch.direction == COOLING and per_cycle:
        offset = offset + (offsets[min(level + 1, len(offsets) - 1)] - offset) * q
    return levels.strain_hot + levels.strain_span * q + offset


def _by_cycle(data):
    cycles = {}
    for b in data.branches:
        if b.complete:
            cycles.setdefault(b.cycle, {})[b.direction] = b
    return cycles


def cycle_rows(data, params, offsets, profile, per_cycle=True):
    """[{file, load_kg, cycle, quantity, unit, data, model}] of one file's complete cycles."""
    rows = []
    for cycle, branches in sorted(_by_cycle(data).items()):
        found = {"data": {}, "model": {}}
        for direction, b in branches.items():
            rows_of = slice(b.start, b.stop)
            found["data"][direction] = branch_tangents(data.smoothed[rows_of], data.strain[rows_of],
                                                       direction)
            low, high = float(profile[rows_of].min()), float(profile[rows_of].max())
            grid = np.linspace(low, high, GRID_POINTS)
            found["model"][direction] = branch_tangents(
                grid, model_branch_strain(grid, b, data, params, offsets, per_cycle), direction)
        numbers = {source: cycle_numbers(found[source].get(HEATING), found[source].get(COOLING))
                   for source in found}
        for quantity, unit in QUANTITIES:
            rows.append({"file": data.path.name, "load_kg": data.load, "cycle": cycle,
                         "quantity": quantity, "unit": unit,
                         "data": numbers["data"][quantity], "model": numbers["model"][quantity]})
    return rows


def _text(value, digits=4):
    return "" if value is None or (isinstance(value, float) and math.isnan(value)) else \
        f"{value:.{digits}g}"


def rows_csv(rows):
    """CSV text of :func:`cycle_rows` rows (NaN as an empty cell)."""
    stream = io.StringIO(newline="")
    writer = csv.writer(stream, lineterminator="\n")
    writer.writerow(["file", "load_kg", "cycle", "quantity", "unit", "data", "model"])
    for row in rows:
        writer.writerow([row["file"], repr(row["load_kg"]), row["cycle"], row["quantity"],
                         row["unit"], _text(row["data"], 8), _text(row["model"], 8)])
    return stream.getvalue()


def rows_markdown(rows):
    """Markdown tables of :func:`cycle_rows` rows, one per file, data and model side by side."""
    lines = ["# Transformation temperatures per cycle (tangent-line construction)", "",
             "A_s, A_f on heating and M_s, M_f on cooling where the transformation tangent meets "
             "the baselines; thermal hysteresis = heating minus cooling temperature at half the "
             "actuation strain; actuation strain recovered on heating; residual strain left by "
             "the cycle at its lowest temperature. Empty: the branch does not show the whole "
             "transformation."]
    files = []
    for row in rows:
        if (row["file"], row["load_kg"]) not in files:
            files.append((row["file"], row["load_kg"]))
    for name, load in files:
        lines += ["", f"## {name} (load {load:g} kg)", "",
                  "| cycle | quantity | unit | data | model | model - data |",
                  "|---:|---|---|---:|---:|---:|"]
        for row in rows:
            if (row["file"], row["load_kg"]) != (name, load):
                continue
            difference = row["model"] - row["data"]
            lines.append(f"| {row['cycle']} | {row['quantity']} | {row['unit']} | "
                         f"{_text(row['data'])} | {_text(row['model'])} | {_text(difference, 2)} |")
    return "\n".join(lines) + "\n"
