"""Per-cycle transformation temperatures, actuation, hysteresis and residual strain: data vs model.

The same tangent construction (:mod:`sma_fmu.identification.transformation_temperatures`)
runs on the data twice, against the smoothed measured temperature (what a lab reports) and
against the fitted wire temperature (the thermocouple's lag removed), and on the fitted model
(each branch's model curve, with that cycle's residual-strain offsets, on a 2,000-point grid
over the wire branch's temperature range), so data at the wire temperature and model differ
only by the fit, not by the method. Written as CSV (one row per file, cycle and quantity) and as
Markdown (one table per file). Where the construction cannot be made the cell gives the
reason (for example "transformation not finished before the turn"), never an empty cell.
"""
import csv
import io
import math

import numpy as np

from sma_fmu.identification.isobaric.missing import Reasons
from sma_fmu.identification.isobaric.terms import branch_curve
from sma_fmu.identification.transformation_temperatures import (QUANTITIES,
                                                                branch_tangents_or_reason,
                                                                cycle_numbers)
from sma_fmu.runtime.constants import COOLING, HEATING

__all__ = ["model_branch_strain", "cycle_rows", "rows_csv", "rows_markdown", "SOURCES"]

GRID_POINTS = 2000
SOURCES = ("data", "data_wire", "model")


def model_branch_strain(temperature, branch, data, params, offsets, per_cycle=True):
    """Model strain [1] of one branch at ``temperature`` [degC], with its offsets [1]."""
    strain, _, q = branch_curve(temperature, data.load, branch.direction, params,
                                data.reference_length)
    level = branch.level if per_cycle else 0
    offset = offsets[min(level, len(offsets) - 1)]
    if branch.direction == COOLING and per_cycle:
        offset = offset + (offsets[min(level + 1, len(offsets) - 1)] - offset) * q
    return strain + offset


_NEEDS = {"A_s": (HEATING,), "A_f": (HEATING,), "actuation_strain": (HEATING,),
          "M_s": (COOLING,), "M_f": (COOLING,), "thermal_hysteresis": (HEATING, COOLING),
          "residual_strain": (HEATING, COOLING)}
_WORD = {HEATING: "heating", COOLING: "cooling"}


def _by_cycle(data):
    """{cycle: {direction: (index, branch)}} of the cycles with at least one complete branch."""
    cycles = {}
    for index, b in enumerate(data.branches):
        cycles.setdefault(b.cycle, {})[b.direction] = (index, b)
    return {c: found for c, found in cycles.items() if any(b.complete for _, b in found.values())}


def _reasons(found, reasons, quantity):
    """Why ``quantity`` has no value: the first missing branch's reason."""
    for direction in _NEEDS[quantity]:
        if found.get(direction) is None:
            return f"{_WORD[direction]}: {reasons[direction]}"
    return ""


def cycle_rows(data, params, offsets, profile, per_cycle=True, wire_bounds=None):
    """[{file, load_kg, cycle, quantity, unit, data, data_wire, model, and a ``*_note`` for each
    of the three}] of one file's cycles with a complete branch; a note says why a value is
    missing (NaN). ``data``: strain against the measured (smoothed) temperature, what a lab
    reports; ``data_wire``: against the fitted wire temperature, the model's footing.

    ``profile`` is the fitted wire temperature [degC]; ``wire_bounds`` the wire branches'
    first rows (from the fit; default: the data's branches), over whose temperature range the
    model branch is drawn.
    """
    bounds = wire_bounds if wire_bounds is not None else \
        [b.start for b in data.branches] + [data.branches[-1].stop]
    rows = []
    for cycle, branches in sorted(_by_cycle(data).items()):
        found = {"data": {}, "data_wire": {}, "model": {}}
        reasons = {"data": {}, "data_wire": {}, "model": {}}
        for direction in (HEATING, COOLING):
            if direction not in branches:
                for source in found:
                    reasons[source][direction] = "no such branch in this cycle (the file " \
                        "starts or ends there, or --cycles cut it)"
                continue
            index, b = branches[direction]
            if not b.complete:
                for source in found:
                    reasons[source][direction] = "branch covers under 70 % of the " \
                        "temperature range (incomplete)"
                continue
            of = slice(b.start, b.stop)
            found["data"][direction], reasons["data"][direction] = branch_tangents_or_reason(
                data.smoothed[of], data.strain[of], direction)
            of = slice(bounds[index], bounds[index + 1])
            found["data_wire"][direction], reasons["data_wire"][direction] = \
                branch_tangents_or_reason(profile[of], data.strain[of], direction)
            grid = np.linspace(float(profile[of].min()), float(profile[of].max()), GRID_POINTS)
            found["model"][direction], reason = branch_tangents_or_reason(
                grid, model_branch_strain(grid, b, data, params, offsets, per_cycle), direction)
            reasons["model"][direction] = reason and f"{reason}, over the wire's " \
                f"{grid[0]:.4g} to {grid[-1]:.4g} degC"
        numbers = {source: cycle_numbers(found[source].get(HEATING), found[source].get(COOLING))
                   for source in found}
        for quantity, unit in QUANTITIES:
            row = {"file": data.path.name, "load_kg": data.load, "cycle": cycle,
                   "quantity": quantity, "unit": unit}
            for source in found:
                row[source] = numbers[source][quantity]
                row[f"{source}_note"] = "" if math.isfinite(row[source]) else \
                    _reasons(found[source], reasons[source], quantity)
            rows.append(row)
    return rows


def _text(value, digits=4):
    return "" if value is None or (isinstance(value, float) and math.isnan(value)) else \
        f"{value:.{digits}g}"


def rows_csv(rows):
    """CSV text of :func:`cycle_rows` rows (NaN as an empty cell, its reason in the note)."""
    stream = io.StringIO(newline="")
    writer = csv.writer(stream, lineterminator="\n")
    writer.writerow(["file", "load_kg", "cycle", "quantity", "unit"] + list(SOURCES)
                    + [f"{source}_note" for source in SOURCES])
    for row in rows:
        writer.writerow([row["file"], repr(row["load_kg"]), row["cycle"], row["quantity"],
                         row["unit"]] + [_text(row[source], 8) for source in SOURCES]
                        + [row[f"{source}_note"] for source in SOURCES])
    return stream.getvalue()


def rows_markdown(rows):
    """Markdown tables of :func:`cycle_rows` rows, one per file, data and model side by side;
    a value that cannot be had reads "n/a [k]", its reason k listed once under the table."""
    lines = ["# Transformation temperatures per cycle (tangent-line construction)", "",
             "A_s, A_f on heating and M_s, M_f on cooling where the transformation tangent meets "
             "the baselines; thermal hysteresis = heating minus cooling temperature at half the "
             "actuation strain; actuation strain recovered on heating; residual strain left by "
             "the cycle at its lowest temperature. Data: strain against the measured (smoothed) "
             "temperature; data, wire T: against the fitted wire temperature (the thermocouple's "
             "lag removed), the footing of the model and of model - data. n/a [k]: the "
             "construction cannot be made; why is listed once under the file's table."]
    files = []
    for row in rows:
        if (row["file"], row["load_kg"]) not in files:
            files.append((row["file"], row["load_kg"]))
    for name, load in files:
        reasons = []
        lines += ["", f"## {name} (load {load:g} kg)", "",
                  "| cycle | quantity | unit | data | data, wire T | model | model - data, wire T |",
                  "|---:|---|---|---:|---:|---:|---:|"]
        reasons = Reasons()
        for row in rows:
            if (row["file"], row["load_kg"]) != (name, load):
                continue
            cells = [reasons.cell(row[s], row[f"{s}_note"]) for s in SOURCES]
            missing = next((s for s in ("data_wire", "model") if not math.isfinite(row[s])), None)
            difference = reasons.mark(row[f"{missing}_note"]) if missing else \
                _text(row["model"] - row["data_wire"], 2)
            lines.append(f"| {row['cycle']} | {row['quantity']} | {row['unit']} | "
                         f"{' | '.join(cells)} | {difference} |")
        lines += [""] + [f"- {line}" for line in reasons.lines()] if reasons.texts else []
    return "\n".join(lines) + "\n"
