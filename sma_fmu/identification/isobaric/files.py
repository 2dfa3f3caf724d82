"""Read isobaric thermal-cycling files (lab exports) and split them into branches and cycles.

A file is text: optional preamble lines (``#`` comments or ``key: value`` lines), one
column row, then one row per sample in measurement order, as :mod:`~.table` reads it (quoted
cells and rows, comma, semicolon, tab or blanks, a decimal comma with semicolons). Columns are
found by their names (:mod:`~.columns`: case, brackets and quotes ignored; other columns are
ignored):

| quantity | names start with | units (from the name; default first) |
|---|---|---|
| temperature | ``temp``, ``T_`` | C (``C``, ``degC``, ``°C``), K, F |
| strain | ``strain``, ``eps`` | fraction (``1``, ``mm/mm``), percent (``%``, ``pct``) |
| length | ``length``, ``L_`` | m, mm, um |
| extension | ``extension``, ``elongation``, ``displacement`` | m, mm, um |
| resistance (optional) | ``resistance``, ``R_`` | ohm |
| time (optional) | ``time`` | s, ms, min, h |
| stress (optional) | ``stress`` | MPa, kPa, GPa, Pa, psi, ksi (per row) |

Exactly one of strain, length or extension (length and extension over the reference length;
the file's load from the stress column's median); a strain both in percent (``Strain_p``, ``%``)
and as a fraction is read twice and the finer one used. A stress column's load ramp (and
unloading) is left out first (:mod:`~.stress`, which also checks its limit and spread); a time
column may repeat stamps at its resolution (:mod:`~.timebase`). What reading changed or
assumed is in ``notes`` (the fit and predict print them and keep them in their reports).
Values are checked against their unit ("mismatched units"): degC readings all >= 200 look
like kelvin, kelvin readings below 150 like degC, a fraction beyond +-1 like percent, a
percentage spanning under 0.05 % like a fraction, a length [m] far from the reference length
like millimetres (and back).
The load comes from the caller or a preamble line ``load: 0.15 kg`` (g and N too) or
``stress: 83 MPa``.

Branches and cycles: :mod:`sma_fmu.identification.isobaric.cycles` (scales from the
temperature's dominant period, so 2 and 1,000 cycles per file read alike); ``cycles``
keeps a range of them. The ``smoothed`` temperature kept for the tangent construction is
filtered again over the square root of the median branch length.
"""
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from sma_fmu.identification.isobaric.columns import SCALE, choose_strain, find_columns, read_as
from sma_fmu.identification.isobaric.cycles import (Branch, select_cycles, smooth,
                                                   split_branches)
from sma_fmu.identification.isobaric.end_step import end_step
from sma_fmu.identification.isobaric.resolution import written_step
from sma_fmu.identification.isobaric.stress import constant_load_rows, file_stress
from sma_fmu.identification.isobaric.synthetic import load_of_stress, stress_of_load
from sma_fmu.identification.isobaric.table import number, plain, read_table
from sma_fmu.identification.isobaric.timebase import time_seconds
from sma_fmu.identification.limits import MAX_LOAD_KG, MAX_STRESS_MPA
from sma_fmu.identification.measurements import MeasurementError
from sma_fmu.runtime.constants import COOLING, HEATING, KELVIN_OFFSET, STANDARD_GRAVITY

__all__ = ["Branch", "IsobaricData", "read_isobaric", "noise_level"]

MIN_STRAIN_SPAN = 1e-3            # a complete branch must change the strain by this much [1]


@dataclass
class IsobaricData:
    """One file: columns converted to degC, strain [1] (relative to ``reference_length``), ohm, s."""

    path: Path
    load: float                 # kg
    reference_length: float     # m
    absolute: bool              # strain zero meaningful (length column) or arbitrary
    columns: dict               # quantity -> (column name, unit)
    temperature: np.ndarray
    strain: np.ndarray
    resistance: np.ndarray      # or None
    time: np.ndarray            # or None
    smoothed: np.ndarray        # smoothed temperature [degC]
    branches: list
    splitting: object = None    # cycles.Splitting: how the branches were found
    strain_note: str = ""       # which of two strain columns was used, and why
    stress_column: float = None  # median of the file's stress column [MPa], if it has one
    notes: list = field(default_factory=list)   # what reading left out or assumed, in words
    reference_source: str = ""  # where reference_length came from
    resolution: dict = field(default_factory=dict)  # quantity -> {"written" step, its "unit",
    #                                                  "step" in the data's units}, see resolution

    @property
    def levels(self):
        """Number of residual-strain levels (1 + the cooling branches)."""
        return 1 + sum(1 for b in self.branches if b.direction == COOLING)


def _metadata_load(path, lines, diameter):
    """Load [kg] stated in preamble lines, or None; raises beyond the limits of --load and
    --stress."""
    for line in lines:
        text = line.lstrip("#%/! ").lower()
        match = re.search(r"\b(load|mass|force)\s*[:=,]?\s*([-+0-9.eE]+)\s*(kg|g|n)\b", text)
        if match:
            value, unit = float(match.group(2)), match.group(3)
            load = value * {"kg": 1.0, "g": 1e-3, "n": 1.0 / STANDARD_GRAVITY}[unit]
            if load > MAX_LOAD_KG:
                raise MeasurementError(f"{path}: header line {line!r}: {plain(load)} kg is "
                                       f"above {MAX_LOAD_KG:g} kg, the most --load accepts")
            return load
        match = re.search(r"\bstress\s*[:=,]?\s*([-+0-9.eE]+)\s*mpa\b", text)
        if match:
            stress = float(match.group(1))
            if stress > MAX_STRESS_MPA:
                raise MeasurementError(f"{path}: header line {line!r}: {plain(stress)} MPa is "
                                       f"above {MAX_STRESS_MPA:g} MPa, the most --stress accepts")
            return load_of_stress(stress, diameter)
    return None


def _numbers(path, names, rows, index, decimal_comma):
    """(values, cells) of column ``index`` of ``rows``; raises naming the line of a bad cell."""
    values, texts = np.empty(len(rows)), []
    for k, (line, cells) in enumerate(rows):
        text = cells[index] if index < len(cells) else ""
        if not text:
            raise MeasurementError(f"{path}: line {line}: column {names[index]} is empty")
        try:
            value = number(text, decimal_comma)
        except ValueError:
            raise MeasurementError(f"{path}: line {line}: {names[index]} = {text!r} "
                                   f"is not a number") from None
        if not math.isfinite(value):
            raise MeasurementError(f"{path}: line {line}: {names[index]} = {text!r} is not finite")
        values[k] = value
        texts.append(text)
    return values, texts


def _unit_error(path, name, values, what):
    return MeasurementError(f"{path}: column {name}: values {values.min():.6g} .. "
                            f"{values.max():.6g} {what} (mismatched units)")


def _temperature(path, name, unit, values):
    if unit == "K":
        if values.min() < 150.0:
            raise _unit_error(path, name, values, "look like degC, not kelvin; name the column "
                                                   "temperature_C")
        return values - KELVIN_OFFSET
    if unit == "F":
        return (values - 32.0) / 1.8
    if values.min() >= 200.0:
        raise _unit_error(path, name, values, "look like kelvin, not degC; name the column "
                                               "temperature_K")
    if values.min() <= -KELVIN_OFFSET:
        raise _unit_error(path, name, values, "go below absolute zero")
    return values


def _strain(path, quantity, name, unit, values, reference, in_file=None):
    """``values`` of the column ``name`` [``unit``] as strain [1]; ``in_file``: the column's
    name in the file (for the ``--column`` hint), when ``name`` is how it is read."""
    if quantity == "strain":
        if unit == "fraction" and np.abs(values).max() > 1.0:
            raise _unit_error(path, name, values, f"exceed 1: they look like percent; name the "
                                                   f"column strain_percent (or read it so: "
                                                   f"--column strain_percent="
                                                   f"{in_file or name!r})")
        if unit == "percent" and np.ptp(values) < 0.05:
            raise _unit_error(path, name, values, "span under 0.05 %: they look like a fraction "
                                                   "(then name the column strain), or the wire "
                                                   "never transforms")
        return values / 100.0 if unit == "percent" else values
    metres = values * SCALE[unit]
    if quantity == "extension":
        if np.abs(metres).max() > 0.5 * reference:
            raise _unit_error(path, name, values, f"[{unit}] are over half the reference length "
                                                   f"{reference:g} m (give --reference-length, or "
                                                   f"the unit m or mm in the column name)")
        return metres / reference
    median = float(np.median(metres))
    if not 0.5 * reference < median < 2.0 * reference:
        raise _unit_error(path, name, values, f"[{unit}] are far from the reference length "
                                               f"{reference:g} m (give --reference-length, or "
                                               f"the unit m or mm in the column name)")
    return metres / reference - 1.0


def noise_level(values):
    """Standard deviation of white noise on a smooth signal: MAD of second differences."""
    second = np.diff(np.asarray(values, dtype=float), 2)
    if second.size == 0:
        return 0.0
    return float(1.4826 * np.median(np.abs(second - np.median(second))) / math.sqrt(6.0))


def _constant_load(path, table, columns, given):
    """(slice of the rows at constant load, stress [MPa] or None, notes): a stress column's
    load ramp and unloading left out, its limit and spread checked (``given``: the stress
    [MPa] the caller gave, or None)."""
    if "stress" not in columns:
        return slice(None), None, []
    index, unit = columns["stress"]
    name = table.names[index]
    values = _numbers(path, table.names, table.rows, index, table.decimal_comma)[0] * SCALE[unit]
    lines = np.array([line for line, _ in table.rows])
    keep, notes = constant_load_rows(name, values, lines, unit)
    stress, checked = file_stress(path, name, values[keep], lines[keep], unit, given)
    return keep, stress, notes + checked


def _reference_notes(shape, name, unit, reference, source, model_length):
    """How a length or extension column became strain, naming the reference length, and
    what a reference length unlike the model's x0 does to the identified wire."""
    notes = []
    if shape != "strain":
        formula = f"{name} / {plain(reference / SCALE[unit])} {unit}" + \
            (" - 1" if shape == "length" else "")
        notes.append(f"strain = {formula}: the reference length {plain(reference)} m "
                     f"({source}; --reference-length sets it)")
    if model_length and abs(reference / model_length - 1.0) > 1e-9:
        notes.append(f"the reference length {plain(reference)} m differs from the model's x0 "
                     f"{plain(model_length)} m: the model's length is compared over "
                     f"{plain(reference)} m too, so its own strain (over x0) is "
                     f"{plain(reference / model_length)} times the data's; give a --model "
                     f"with the specimen's x0 instead")
    return notes


def read_isobaric(path, load=None, reference_length=0.8, diameter=None, cycles=None,
                  reference_source="given", model_length=None, renames=None):
    """Read one isobaric file as :class:`IsobaricData`.

    ``load`` [kg] wins over a load stated in the preamble; ``reference_length`` [m] is the
    length strain is measured from (length and extension columns are converted with it),
    ``reference_source`` says where it came from and ``model_length`` is the model's x0 [m]
    (both for the notes); ``diameter`` [m] converts a preamble ``stress: ... MPa``;
    ``cycles`` = (first, last) cycle numbers to keep (None: all; an end None: open), see
    ``cycles.parse_cycles``; ``renames`` = [(new, old)]: columns read under another name
    (``--column NEW=OLD``; the report shows ``OLD (as NEW)``).
    """
    path = Path(path)
    table = read_table(path)
    if not table.rows:
        raise MeasurementError(f"{path}: no data rows after the column row")
    names = read_as(path, table.names, renames)
    columns = find_columns(path, names)
    names = [name if name == given else f"{given} (as {name})"
             for given, name in zip(table.names, names)]
    diameter = diameter if diameter else 0.15e-3
    given = None if load is None else stress_of_load(load, diameter)
    keep, stress, notes = _constant_load(path, table, columns, given)
    rows = table.rows[keep]

    steps = {}

    def column(quantity):
        """A column's values on the rows at constant load (its written step kept in ``steps``)."""
        values, texts = _numbers(path, names, table.rows, columns[quantity][0], table.decimal_comma)
        steps[quantity] = written_step(texts, table.decimal_comma)
        return values[keep]

    def resolution(quantity, raw, converted):
        """{"written", "unit", "step"} of a column: its written step, and that step in the data's
        units (the conversions are linear: scaled by the ratio of the spans)."""
        span = float(np.ptp(raw))
        scale = float(np.ptp(converted)) / span if span > 0 else 1.0
        unit = columns[quantity][1]
        return {"written": steps[quantity], "unit": "K" if unit == "C" else unit,
                "step": steps[quantity] * scale}

    t_index, t_unit = columns["temperature"]
    raw = column("temperature")
    temperature = _temperature(path, names[t_index], t_unit, raw)
    written = {"temperature": resolution("temperature", raw, temperature)}
    shape = next(q for q in ("strain", "length", "extension") if q in columns)
    s_index, s_unit = columns[shape]
    raw = column(shape)
    strain = _strain(path, shape, names[s_index], s_unit, raw, reference_length,
                     table.names[s_index])
    written["strain"] = resolution(shape, raw, strain)
    notes += _reference_notes(shape, names[s_index], s_unit, reference_length, reference_source,
                              model_length)
    strain_note = ""
    if "strain_other" in columns:
        o_index, o_unit = columns["strain_other"]
        raw = column("strain_other")
        other = _strain(path, "strain", names[o_index], o_unit, raw, reference_length,
                        table.names[o_index])
        strain, chosen, strain_note = choose_strain(path, (names[s_index], strain),
                                                    (names[o_index], other))
        if chosen != names[s_index]:
            written["strain"] = resolution("strain_other", raw, other)
            columns["strain"] = columns.pop("strain_other")
        else:
            columns.pop("strain_other")
    resistance = column("resistance") if "resistance" in columns else None
    if resistance is not None:
        written["resistance"] = resolution("resistance", resistance, resistance)
    if resistance is not None and not (resistance > 0).all():
        bad = int(np.argmin(resistance))
        raise MeasurementError(f"{path}: line {rows[bad][0]}: {names[columns['resistance'][0]]} "
                               f"= {plain(resistance[bad])} ohm must be > 0")
    time = None
    if "time" in columns:
        index, unit = columns["time"]
        values, texts = _numbers(path, names, table.rows, index, table.decimal_comma)
        seconds, time_notes = time_seconds(path, names[index], unit, values, texts,
                                           [line for line, _ in table.rows])
        time, notes = seconds[keep], notes + time_notes    # spread on every row, then cut

    def rows_kept(kept):
        """The per-row columns on the rows ``kept`` (a slice)."""
        return (temperature[kept], strain[kept], rows[kept],
                resistance[kept] if resistance is not None else None,
                time[kept] if time is not None else None)

    cut, cut_note = end_step(strain, temperature, [line for line, _ in rows])
    if cut_note:
        temperature, strain, rows, resistance, time = rows_kept(cut)
        notes.append(cut_note)
    if len(rows) < 50:
        raise MeasurementError(f"{path}: only {len(rows)} data rows; a thermal cycle needs more")
    if load is None and stress is not None:
        load = load_of_stress(stress, diameter)
    if load is None:
        load = _metadata_load(path, table.preamble, diameter)
        if load is None:
            raise MeasurementError(f"{path}: no load given: pass --load KG or --stress MPa, give "
                                   f"a stress column (stress_MPa), or state it in the header "
                                   f"(# load: 0.15 kg)")
    if not load >= 0:
        raise MeasurementError(f"{path}: load = {plain(load)} kg must be >= 0")
    branches, _, splitting = split_branches(temperature, path)
    if cycles is not None:
        keep, branches = select_cycles(branches, cycles, path)
        splitting.selected = f"{cycles[0] or 1} to {cycles[1] or 'the last'}"
        temperature, strain, rows, resistance, time = rows_kept(keep)
    # the tangent construction gets a smoother signal, over the square root of the median
    # branch length (ASMADA's rule): a ramp bends where the transformation's latent heat
    # slows it, and a wider window (a quarter branch) moved the heating tangents by 3-5 K
    smoothed = smooth(temperature, round(math.sqrt(np.median([b.stop - b.start
                                                              for b in branches]))))
    for b in branches:
        if b.complete and np.ptp(strain[b.start:b.stop]) < MIN_STRAIN_SPAN:
            raise MeasurementError(
                f"{path}: no transformation in range: on the {_NAMES[b.direction]} branch "
                f"(lines {rows[b.start][0]}-{rows[b.stop - 1][0]}, {smoothed[b.start]:.4g} -> "
                f"{smoothed[b.stop - 1]:.4g} degC) the strain changes by only "
                f"{np.ptp(strain[b.start:b.stop]):.3g} (at least {MIN_STRAIN_SPAN:g} needed)")
    units = {q: (names[i], u) for q, (i, u) in columns.items()}
    return IsobaricData(path, float(load), float(reference_length), shape == "length", units,
                        temperature, strain, resistance, time, smoothed, branches, splitting,
                        strain_note, stress, notes, reference_source, written)


_NAMES = {HEATING: "heating", COOLING: "cooling"}
