"""Read isobaric thermal-cycling files (lab exports) and split them into branches and cycles.

A file is text: optional preamble lines (``#`` comments or ``key: value`` lines), one
column row, then one row per sample in measurement order. Delimiter: comma, semicolon,
tab or blanks (the column row decides; with semicolons a decimal comma is accepted).
Columns are found by their names (case and brackets ignored; other columns are ignored):

| quantity | names start with | units (from the name; default first) |
|---|---|---|
| temperature | ``temp``, ``T_`` | C (``C``, ``degC``, ``°C``), K, F |
| strain | ``strain``, ``eps`` | fraction (``1``, ``mm/mm``), percent (``%``, ``percent``, ``pct``) |
| length | ``length``, ``L_`` | m, mm |
| extension | ``extension``, ``elongation``, ``displacement`` | m, mm (added to the reference length) |
| resistance (optional) | ``resistance``, ``R_`` | ohm |
| time (optional) | ``time`` | s, ms, min, h |
| stress (optional) | ``stress`` | MPa (per row; the file's load from its median) |

Exactly one of strain, length or extension; a strain both in percent (``Strain_p``, ``%``)
and as a fraction is read twice and the finer one used (:mod:`~.columns`, which also checks
separators and the stress column). Values are checked against their unit
("mismatched units"): degC readings all >= 200 look like kelvin, kelvin readings below
150 like degC, a fraction beyond +-1 like percent, a percentage spanning under 0.05 % like a
fraction, a length [m] far from the reference length like millimetres (and back).
The load comes from the caller or a preamble line ``load: 0.15 kg`` (g and N too) or
``stress: 83 MPa``.

Branches and cycles: :mod:`sma_fmu.identification.isobaric.cycles` (scales from the
temperature's dominant period, so 2 and 1,000 cycles per file read alike); ``cycles``
keeps a range of them. The ``smoothed`` temperature kept for the tangent construction is
filtered again over a quarter of the median branch length.
"""
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from sma_fmu.identification.isobaric.columns import check_separators, choose_strain, file_stress
from sma_fmu.identification.isobaric.cycles import (Branch, select_cycles, smooth,
                                                   split_branches)
from sma_fmu.identification.isobaric.synthetic import load_of_stress
from sma_fmu.identification.measurements import MeasurementError
from sma_fmu.runtime.constants import COOLING, HEATING, KELVIN_OFFSET, STANDARD_GRAVITY

__all__ = ["Branch", "IsobaricData", "read_isobaric", "noise_level"]

MIN_STRAIN_SPAN = 1e-3            # a complete branch must change the strain by this much [1]
_COMMENT = ("#", "%", "//", "!")
_QUANTITIES = {
    "temperature": (("temp",), ("t",), {"": "C", "c": "C", "degc": "C", "celsius": "C",
                                        "k": "K", "kelvin": "K", "f": "F", "degf": "F"}),
    "strain": (("strain", "eps"), (), {"": "fraction", "1": "fraction", "mm/mm": "fraction",
                                       "fraction": "fraction", "%": "percent", "p": "percent",
                                       "percent": "percent", "pct": "percent"}),
    "stress": (("stress",), (), {"": "MPa", "mpa": "MPa"}),
    "length": (("length",), ("l",), {"": "m", "m": "m", "mm": "mm"}),
    "extension": (("extension", "elongation", "displacement"), (), {"": "m", "m": "m", "mm": "mm"}),
    "resistance": (("resist",), ("r",), {"": "ohm", "ohm": "ohm", "ohms": "ohm", "Ω": "ohm"}),
    "time": (("time",), (), {"": "s", "s": "s", "sec": "s", "ms": "ms", "min": "min", "h": "h"}),
}
_SCALE = {"ms": 1e-3, "s": 1.0, "min": 60.0, "h": 3600.0, "m": 1.0, "mm": 1e-3}


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

    @property
    def levels(self):
        """Number of residual-strain levels (1 + the cooling branches)."""
        return 1 + sum(1 for b in self.branches if b.direction == COOLING)


def _split(line, delimiter):
    return [cell.strip() for cell in (line.split(delimiter) if delimiter else line.split())]


def _delimiter(line):
    counts = {d: line.count(d) for d in (",", ";", "\t")}
    best = max(counts, key=counts.get)
    return best if counts[best] else None


def _float(text, decimal_comma):
    if decimal_comma:
        text = text.replace(",", ".")
    return float(text)


def _is_number(text, decimal_comma=False):
    try:
        return math.isfinite(_float(text, decimal_comma))
    except ValueError:
        return False


def _classify(name):
    """(quantity, unit) of a column name, or None."""
    text = name.strip().replace("°", "deg").replace("Ω", "ohm")
    tokens = [t for t in re.split(r"[^A-Za-z0-9%/]+", text) if t]
    if not tokens:
        return None
    first, rest = tokens[0].lower(), [t.lower() for t in tokens[1:]]
    for quantity, (prefixes, exact, units) in _QUANTITIES.items():
        if any(first.startswith(p) for p in prefixes) or (first in exact and rest):
            unit = next((units[t] for t in rest if t in units), None)
            if unit is None and rest and first in exact:
                continue
            return quantity, unit or units[""]
    return None


def _metadata_load(lines, diameter):
    """Load [kg] stated in preamble lines, or None."""
    for line in lines:
        text = line.lstrip("#%/! ").lower()
        match = re.search(r"\b(load|mass|force)\s*[:=,]?\s*([-+0-9.eE]+)\s*(kg|g|n)\b", text)
        if match:
            value, unit = float(match.group(2)), match.group(3)
            return value * {"kg": 1.0, "g": 1e-3, "n": 1.0 / STANDARD_GRAVITY}[unit]
        match = re.search(r"\bstress\s*[:=,]?\s*([-+0-9.eE]+)\s*mpa\b", text)
        if match:
            return load_of_stress(float(match.group(1)), diameter)
    return None


def _table(path):
    """(preamble lines, column names, [(line number, cells)], decimal comma) of a file."""
    try:
        text = Path(path).read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise MeasurementError(f"{path}: file not found") from None
    except IsADirectoryError:
        raise MeasurementError(f"{path}: is a folder, not a data file") from None
    except UnicodeDecodeError as error:
        raise MeasurementError(f"{path}: not a UTF-8 text file (byte {error.start}: "
                               f"{error.reason})") from None
    except OSError as error:
        raise MeasurementError(f"{path}: cannot read the file: {error.strerror or error}") from None
    lines = [(n, line.strip()) for n, line in enumerate(text.splitlines(), start=1)]
    content = [(n, line) for n, line in lines if line and not line.startswith(_COMMENT)]
    if not content:
        raise MeasurementError(f"{path}: no column row and no data")
    preamble = [line for _, line in lines if line.startswith(_COMMENT)]
    for i, (number, line) in enumerate(content):
        delimiter = _delimiter(line)
        names = _split(line, delimiter)
        numeric = [c for c in names if _is_number(c, True)]
        if len(numeric) == len(names):
            if len(names) < 2:
                raise MeasurementError(f"{path}: line {number}: only one column ({line!r}); "
                                       f"expected temperature and strain columns")
            raise MeasurementError(f"{path}: line {number}: numbers without a column row before "
                                   f"them; expected names such as temperature_C,strain_percent")
        following = _split(content[i + 1][1], delimiter) if i + 1 < len(content) else []
        if (len(names) >= 2 and len(following) == len(names)
                and sum(_is_number(c, True) for c in following) >= 2):
            check_separators(path, delimiter, content[i + 1:])
            rows = [(n, _split(row, delimiter)) for n, row in content[i + 1:]]
            return preamble, names, rows, delimiter == ";"
        if len(names) < 2 and i + 1 < len(content) and len(following) < 2 \
                and all(_is_number(c, True) for c in following):
            raise MeasurementError(f"{path}: line {number}: only one column ({names[0]!r}); "
                                   f"expected temperature and strain columns")
        preamble.append(line)     # a "key: value" line before the column row
    raise MeasurementError(f"{path}: no column row found")


def _columns(path, names):
    found = {}
    for index, name in enumerate(names):
        kind = _classify(name)
        if kind is None:
            continue
        quantity, unit = kind
        if quantity == "strain" and "strain" in found and "strain_other" not in found \
                and unit != found["strain"][1]:
            found["strain_other"] = (index, unit)   # the strain twice: % and fraction
            continue
        if quantity in found:
            raise MeasurementError(f"{path}: line 1: two {quantity} columns, "
                                   f"{names[found[quantity][0]]!r} and {name!r}; keep one")
        found[quantity] = (index, unit)
    if "temperature" not in found:
        raise MeasurementError(f"{path}: no temperature column among {', '.join(names)}; name it "
                               f"e.g. temperature_C or temperature_K")
    shapes = [q for q in ("strain", "length", "extension") if q in found]
    if len(shapes) != 1:
        what = "no strain, length or extension column" if not shapes else \
            f"both {' and '.join(shapes)} columns"
        raise MeasurementError(f"{path}: {what} among {', '.join(names)}; give one of "
                               f"strain_percent, strain, length_m, extension_mm")
    return found


def _numbers(path, names, rows, index, decimal_comma):
    values = np.empty(len(rows))
    for k, (number, cells) in enumerate(rows):
        text = cells[index] if index < len(cells) else ""
        if not text:
            raise MeasurementError(f"{path}: line {number}: column {names[index]} is empty")
        try:
            value = _float(text, decimal_comma)
        except ValueError:
            raise MeasurementError(f"{path}: line {number}: {names[index]} = {text!r} "
                                   f"is not a number") from None
        if not math.isfinite(value):
            raise MeasurementError(f"{path}: line {number}: {names[index]} = {text!r} is not finite")
        values[k] = value
    return values


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


def _strain(path, quantity, name, unit, values, reference):
    if quantity == "strain":
        if unit == "fraction" and np.abs(values).max() > 1.0:
            raise _unit_error(path, name, values, "exceed 1: they look like percent; name the "
                                                   "column strain_percent")
        if unit == "percent" and np.ptp(values) < 0.05:
            raise _unit_error(path, name, values, "span under 0.05 %: they look like a fraction "
                                                   "(then name the column strain), or the wire "
                                                   "never transforms")
        return values / 100.0 if unit == "percent" else values
    metres = values * _SCALE[unit]
    if quantity == "extension":
        if np.abs(metres).max() > 0.5 * reference:
            raise _unit_error(path, name, values, f"[{unit}] are over half the reference length "
                                                   f"{reference:g} m")
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


def read_isobaric(path, load=None, reference_length=0.8, diameter=None, cycles=None):
    """Read one isobaric file as :class:`IsobaricData`.

    ``load`` [kg] wins over a load stated in the preamble; ``reference_length`` [m] is the
    length strain is measured from (length and extension columns are converted with it);
    ``diameter`` [m] converts a preamble ``stress: ... MPa``; ``cycles`` = (first, last)
    cycle numbers to keep (None: all; an end None: open), see ``cycles.parse_cycles``.
    """
    path = Path(path)
    preamble, names, rows, decimal_comma = _table(path)
    if not rows:
        raise MeasurementError(f"{path}: no data rows after the column row")
    columns = _columns(path, names)

    def column(quantity):
        index, _ = columns[quantity]
        return _numbers(path, names, rows, index, decimal_comma)

    t_index, t_unit = columns["temperature"]
    temperature = _temperature(path, names[t_index], t_unit, column("temperature"))
    shape = next(q for q in ("strain", "length", "extension") if q in columns)
    s_index, s_unit = columns[shape]
    strain = _strain(path, shape, names[s_index], s_unit, column(shape), reference_length)
    strain_note = ""
    if "strain_other" in columns:
        o_index, o_unit = columns["strain_other"]
        other = _strain(path, "strain", names[o_index], o_unit, column("strain_other"),
                        reference_length)
        strain, chosen, strain_note = choose_strain(path, (names[s_index], strain),
                                                    (names[o_index], other))
        if chosen != names[s_index]:
            columns["strain"] = columns.pop("strain_other")
        else:
            columns.pop("strain_other")
    stress = None
    if "stress" in columns:
        stress = file_stress(path, names[columns["stress"][0]], column("stress"))
    resistance = column("resistance") if "resistance" in columns else None
    if resistance is not None and not (resistance > 0).all():
        bad = int(np.argmin(resistance))
        raise MeasurementError(f"{path}: line {rows[bad][0]}: {names[columns['resistance'][0]]} = "
                               f"{resistance[bad]!r} must be > 0")
    time = None
    if "time" in columns:
        time = column("time") * _SCALE[columns["time"][1]]
        backwards = np.nonzero(np.diff(time) <= 0)[0]
        if backwards.size:
            k = int(backwards[0]) + 1
            raise MeasurementError(f"{path}: line {rows[k][0]}: {names[columns['time'][0]]} = "
                                   f"{time[k]!r} does not increase; rows must be in time order")
    if len(rows) < 50:
        raise MeasurementError(f"{path}: only {len(rows)} data rows; a thermal cycle needs more")
    if load is None and stress is not None:
        load = load_of_stress(stress, diameter if diameter else 0.15e-3)
    if load is None:
        load = _metadata_load(preamble, diameter if diameter else 0.15e-3)
        if load is None:
            raise MeasurementError(f"{path}: no load given: pass --load KG or --stress MPa, give "
                                   f"a stress column (stress_MPa), or state it in the header "
                                   f"(# load: 0.15 kg)")
    if not load >= 0:
        raise MeasurementError(f"{path}: load = {load!r} kg must be >= 0")
    branches, _, splitting = split_branches(temperature, path)
    if cycles is not None:
        keep, branches = select_cycles(branches, cycles, path)
        splitting.selected = f"{cycles[0] or 1} to {cycles[1] or 'the last'}"
        temperature, strain, rows = temperature[keep], strain[keep], rows[keep]
        resistance = resistance[keep] if resistance is not None else None
        time = time[keep] if time is not None else None
    # the tangent construction gets a smoother signal: a quarter of a branch (a ramp is
    # smooth; the turning points, where the window bends it, lie outside the transformation)
    smoothed = smooth(temperature, int(np.median([b.stop - b.start for b in branches])) // 4)
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
                        strain_note, stress)


_NAMES = {HEATING: "heating", COOLING: "cooling"}
