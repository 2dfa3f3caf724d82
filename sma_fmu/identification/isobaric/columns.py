"""Column checks of isobaric files beyond one quantity per column: mixed separators, a strain
given twice (in percent and as a fraction), and a stress column.

- Separators: the column row decides (comma, semicolon, tab or blanks); a data row with
  another separator (or without the column row's) is an error naming the line. With blanks,
  tabs count as blanks; with semicolons, commas are decimal commas.
- Strain twice: files such as the NiTiHf ones carry ``Strain_p`` [%] and ``Strain`` [1].
  Both are read and must agree to within their resolution; the one with the finer
  resolution (the smallest step between its distinct values, as a fraction) is used, and the
  report says which and why.
- Stress [MPa]: per row. The file's load is the median stress's (with the wire's diameter),
  unless ``--load`` or ``--stress`` gives one; a stress that moves more than 10 % inside the
  file (the medians of ten consecutive blocks of rows span more than 10 % of the file's
  median) is an error: one load per file is what the fit assumes.
"""
import numpy as np

from sma_fmu.identification.measurements import MeasurementError

__all__ = ["check_separators", "choose_strain", "file_stress", "STRESS_SPREAD"]

STRESS_SPREAD = 0.10
_WORD = {",": "commas", ";": "semicolons", "\t": "tabs", None: "blanks"}


def check_separators(path, delimiter, lines):
    """Raise naming the first of ``lines`` [(number, text)] separated unlike the column row."""
    foreign = [d for d in (",", ";", "\t") if d != delimiter
               and not (delimiter == ";" and d == ",") and not (delimiter is None and d == "\t")]
    for number, line in lines:
        for d in foreign:
            if d in line:
                raise MeasurementError(f"{path}: line {number}: separated by {_WORD[d]}, but the "
                                       f"column row by {_WORD[delimiter]}; use one separator "
                                       f"throughout the file")
        if delimiter is not None and delimiter not in line:
            raise MeasurementError(f"{path}: line {number}: no {_WORD[delimiter][:-1]} in "
                                   f"{line[:40]!r}, but the column row is separated by "
                                   f"{_WORD[delimiter]}; use one separator throughout the file")


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


def file_stress(path, name, values):
    """Median stress [MPa] of a stress column; raises when it moves more than STRESS_SPREAD."""
    median = float(np.median(values))
    if not median > 0:
        raise MeasurementError(f"{path}: column {name}: median stress {median:.4g} MPa must be > 0")
    blocks = [float(np.median(part)) for part in np.array_split(values, 10) if part.size]
    spread = (max(blocks) - min(blocks)) / median
    if spread > STRESS_SPREAD:
        raise MeasurementError(f"{path}: column {name}: the stress moves from {min(blocks):.4g} to "
                               f"{max(blocks):.4g} MPa inside the file ({100 * spread:.0f} % of its "
                               f"median {median:.4g} MPa; at most {100 * STRESS_SPREAD:.0f} %): "
                               f"the fit needs one load per file")
    return median
