"""Which quantity each column of an isobaric file holds, from its name, and a strain given twice.

Names: case, brackets, quotes and blanks do not matter; the first word says the quantity and
any later word its unit (``"Temperature (°C)"``, ``Temp [K]``, ``time_s``, ``"Time (h)"``,
``Extension (mm)``, ``Stress (MPa)``). :data:`QUANTITIES` is the table; :data:`SCALE` turns
units into the ones the fit uses (s, m, MPa). Columns it does not know are ignored.

A column whose name says the wrong thing (``Strain`` holding percent, an extensometer
channel ``_Strain1 (mm)``) is read under a name the user gives, ``--column NEW=OLD``
(:func:`read_as`), without editing a lab's file or workbook.

Strain twice: files such as the NiTiHf ones carry ``Strain_p`` [%] and ``Strain`` [1].
Both are read and must agree to within their resolution; the one with the finer resolution
(the smallest step between its distinct values, as a fraction) is used, and the report says
which and why.
"""
import re

import numpy as np

from sma_fmu.identification.measurements import MeasurementError

__all__ = ["QUANTITIES", "SCALE", "classify", "find_columns", "choose_strain", "read_as",
           "KNOWN_NAMES"]

_TEMPERATURE = {"": "C", "c": "C", "degc": "C", "celsius": "C", "k": "K", "kelvin": "K",
                "f": "F", "degf": "F", "fahrenheit": "F"}
_STRAIN = {"": "fraction", "1": "fraction", "mm/mm": "fraction", "m/m": "fraction",
           "fraction": "fraction", "%": "percent", "p": "percent", "percent": "percent",
           "pct": "percent"}
_LENGTH = {"": "m", "m": "m", "mm": "mm", "um": "um", "µm": "um", "micron": "um"}
_STRESS = {"": "MPa", "mpa": "MPa", "n/mm2": "MPa", "n/mm": "MPa", "kpa": "kPa", "gpa": "GPa",
           "pa": "Pa", "psi": "psi", "ksi": "ksi"}
_TIME = {"": "s", "s": "s", "sec": "s", "secs": "s", "second": "s", "seconds": "s", "ms": "ms",
         "min": "min", "mins": "min", "minute": "min", "minutes": "min", "h": "h", "hr": "h",
         "hrs": "h", "hour": "h", "hours": "h"}
# quantity: (first words it starts with, short names that need a unit after them, units)
QUANTITIES = {
    "temperature": (("temp",), ("t",), _TEMPERATURE),
    "strain": (("strain", "eps"), (), _STRAIN),
    "stress": (("stress",), (), _STRESS),
    "length": (("length",), ("l",), _LENGTH),
    "extension": (("extension", "elongation", "displacement"), (), _LENGTH),
    "resistance": (("resist",), ("r",), {"": "ohm", "ohm": "ohm", "ohms": "ohm"}),
    "time": (("time",), (), _TIME),
}
# unit: factor to s, m or MPa
SCALE = {"ms": 1e-3, "s": 1.0, "min": 60.0, "h": 3600.0, "m": 1.0, "mm": 1e-3, "um": 1e-6,
         "MPa": 1.0, "kPa": 1e-3, "GPa": 1e3, "Pa": 1e-6, "psi": 6.894757e-3, "ksi": 6.894757}


def _tokens(name):
    """The words of a column name (symbols spelled out, brackets and blanks dropped)."""
    text = name.strip().replace("°", "deg").replace("Ω", "ohm").replace("²", "2")
    text = text.replace("μ", "µ")      # Greek mu as the micro sign
    return [t for t in re.split(r"[^A-Za-z0-9%/µ]+", text) if t]


def _length_unit(name):
    """The length unit a strain column's name carries instead of a strain unit (an
    extensometer channel named ``_Strain1 (mm)``), or None."""
    rest = [t.lower() for t in _tokens(name)[1:]]
    if any(t in _STRAIN for t in rest):
        return None
    return next((t for t in rest if t and t in _LENGTH), None)


def classify(name):
    """(quantity, unit) of a column name, or None."""
    tokens = _tokens(name)
    if not tokens:
        return None
    first, rest = tokens[0].lower(), [t.lower() for t in tokens[1:]]
    for quantity, (prefixes, exact, units) in QUANTITIES.items():
        if any(first.startswith(p) for p in prefixes) or (first in exact and rest):
            unit = next((units[t] for t in rest if t in units), None)
            if unit is None and rest and first in exact:
                continue
            return quantity, unit or units[""]
    return None


KNOWN_NAMES = "strain, strain_percent, extension_mm, length_m, temperature_C, stress_MPa, time_s"


def read_as(path, names, renames):
    """The names the columns are read under: ``names`` with each (new, old) of ``renames``
    (``--column NEW=OLD``) applied; raises naming the option when OLD is not a column of the
    file or is renamed twice, or NEW says no quantity the reader knows."""
    out = list(names)
    stripped = [name.strip() for name in names]
    given = {}                                   # column index -> the option that renamed it
    for new, old in renames or ():
        option = f"--column {new}={old}"
        if classify(new) is None:
            raise MeasurementError(f"{option}: {new!r} names no quantity the reader knows; "
                                   f"give one such as {KNOWN_NAMES}")
        if old.strip() not in stripped:
            listed = ", ".join(repr(name) for name in names)
            raise MeasurementError(f"{path}: {option}: no column {old!r} among {listed}")
        index = stripped.index(old.strip())
        if index in given:
            raise MeasurementError(f"{option}: column {old!r} is already read as {out[index]!r} "
                                   f"({given[index]}); give one --column for it")
        out[index], given[index] = new, option
    return out


def find_columns(path, names):
    """{quantity: (index, unit)} of the column names; ``strain_other`` for a second strain."""
    found = {}
    for index, name in enumerate(names):
        kind = classify(name)
        if kind is None:
            continue
        quantity, unit = kind
        if quantity == "strain" and _length_unit(name):
            length = _LENGTH[_length_unit(name)]
            raise MeasurementError(f"{path}: column {name!r} is named strain but its unit is "
                                   f"{length}, a length: name it extension_{length} if it holds "
                                   f"the elongation, or length_{length} if it holds the gauge "
                                   f"length (or read it so: --column extension_{length}={name!r})")
        if quantity == "strain" and "strain" in found and "strain_other" not in found \
                and unit != found["strain"][1]:
            found["strain_other"] = (index, unit)   # the strain twice: % and fraction
            continue
        if quantity in found:
            raise MeasurementError(f"{path}: column row: two {quantity} columns, "
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
                               f"strain_percent, strain, length_m, extension_mm (rename it, or "
                               f"--column NEW=OLD)")
    return found


def _resolution(values):
    steps = np.diff(np.unique(values))
    steps = steps[steps > 0]
    return float(steps.min()) if steps.size else 0.0


def choose_strain(path, first, second):
    """(strain [1], name, note) of two strain columns, each (name, values as a fraction)."""
    (name_a, a), (name_b, b) = first, second
    res_a, res_b = _resolution(a), _resolution(b)
    worst = float(np.max(np.abs(a - b)))
    allowed = 2.0 * (res_a + res_b) + 1e-12
    if worst > allowed:
        row = int(np.argmax(np.abs(a - b)))
        raise MeasurementError(f"{path}: columns {name_a} and {name_b} both hold strain but "
                               f"disagree by {worst:.3g} (row {row + 1} of the data; allowed "
                               f"{allowed:.3g}, twice their resolution); keep one")
    (name, values, fine, coarse, other) = (name_a, a, res_a, res_b, name_b) \
        if res_a <= res_b else (name_b, b, res_b, res_a, name_a)
    note = (f"strain from {name} (resolution {fine:.3g}, finer than {other}'s {coarse:.3g}; "
            f"the two agree within {worst:.3g})")
    return values, name, note
