"""The table in an isobaric file's text: preamble, column row and data rows, read by the csv
module, however the lab's machine wrote it (a workbook's sheet is first written out as CSV
text: :mod:`sma_fmu.identification.workbook`).

- Cells quoted or not (``"Time (h)","Temperature (°C)"``): the csv module removes the quotes.
- Whole rows written as one quoted cell, the quotes inside doubled (rows such as
  ``"0.157,23.4,170.759"``, the column row with its quoted names inside), as some exports
  write them: a line the csv module reads as a single quoted cell is read again as the row
  inside it.
- The separator (comma, semicolon, tab or blanks) comes from the csv module's ``Sniffer`` on
  the column row and the rows after it (by counting them in the column row where it cannot
  tell); with semicolons a decimal comma is accepted, with blanks tabs count as blanks. A
  data row with another separator (or without the column row's) is an error naming the line.
- Lines starting with ``#``, ``%``, ``//`` or ``!`` and lines before the column row
  (``key: value``) are the preamble. The column row is the first row followed by a row with as
  many cells, at least two of them numbers.
"""
import csv
import math
from dataclasses import dataclass
from pathlib import Path

from sma_fmu.identification.workbook import refuse_other_spreadsheet, sheet_text, split_sheet
from sma_fmu.identification.measurements import MeasurementError

__all__ = ["Table", "read_table", "number", "is_number", "plain", "check_separators"]

COMMENT = ("#", "%", "//", "!")
SEPARATORS = (",", ";", "\t", " ")
_SNIFF_ROWS = 20              # rows after the column row the Sniffer sees
_WORD = {",": "commas", ";": "semicolons", "\t": "tabs", None: "blanks"}


@dataclass
class Table:
    """Preamble lines, column names, [(line number, cells)] and whether commas are decimal."""

    preamble: list
    names: list
    rows: list
    decimal_comma: bool


def number(text, decimal_comma=False):
    """The float a cell holds (ValueError if none)."""
    return float(text.replace(",", ".") if decimal_comma else text)


def plain(value):
    """A value for a message: a plain number of six significant digits (never a numpy repr)."""
    return f"{value:.6g}"


def is_number(text, decimal_comma=False):
    try:
        return math.isfinite(number(text, decimal_comma))
    except ValueError:
        return False


def check_separators(path, delimiter, lines):
    """Raise naming the first of ``lines`` [(number, text)] separated unlike the column row
    (``delimiter``; None: blanks, where tabs count as blanks; with semicolons commas are
    decimal commas)."""
    foreign = [d for d in (",", ";", "\t") if d != delimiter
               and not (delimiter == ";" and d == ",") and not (delimiter is None and d == "\t")]
    for number_, line in lines:
        for d in foreign:
            if d in line:
                raise MeasurementError(f"{path}: line {number_}: separated by {_WORD[d]}, but "
                                       f"the column row by {_WORD[delimiter]}; use one separator "
                                       f"throughout the file")
        if delimiter is not None and delimiter not in line:
            raise MeasurementError(f"{path}: line {number_}: no {_WORD[delimiter][:-1]} in "
                                   f"{line[:40]!r}, but the column row is separated by "
                                   f"{_WORD[delimiter]}; use one separator throughout the file")


def _text(path):
    refuse_other_spreadsheet(path)
    if split_sheet(path) is not None:
        return sheet_text(path)
    try:
        return Path(path).read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise MeasurementError(f"{path}: file not found") from None
    except IsADirectoryError:
        raise MeasurementError(f"{path}: is a folder, not a data file") from None
    except UnicodeDecodeError as error:
        raise MeasurementError(f"{path}: not a UTF-8 text file (byte {error.start}: "
                               f"{error.reason})") from None
    except OSError as error:
        raise MeasurementError(f"{path}: cannot read the file: {error.strerror or error}") from None


def _unwrapped(line):
    """The row inside a line written as one quoted cell, else the line."""
    if not line.startswith('"'):
        return line
    try:
        cells = next(csv.reader([line], strict=True))
    except csv.Error:
        return line
    return cells[0].strip() if len(cells) == 1 else line


def _separator(lines):
    """(separator or None for blanks, quote character) of the first of ``lines`` and those after."""
    try:
        dialect = csv.Sniffer().sniff("\n".join(lines), delimiters="".join(SEPARATORS))
        found, quote = dialect.delimiter, dialect.quotechar
    except csv.Error:
        counts = {d: lines[0].count(d) for d in SEPARATORS[:3]}
        found, quote = max(counts, key=counts.get), '"'
        found = found if counts[found] else " "
    return (None if found == " " else found), (quote if quote in "\"'" else '"')


def _rows(path, numbered, separator, quote):
    """[(line number, cells)] of ``numbered`` [(line number, text)], one csv reader over all
    of them; a quote left open at the end of a line is an error naming it."""
    lines = [text.replace("\t", " ") if separator is None else text for _, text in numbered]
    reader = csv.reader(lines, delimiter=separator or " ", quotechar=quote, skipinitialspace=True)
    rows = []
    for cells in reader:
        if reader.line_num != len(rows) + 1:
            raise MeasurementError(f"{path}: line {numbered[len(rows)][0]}: a quote opened on "
                                   f"this line is not closed on it")
        rows.append((numbered[len(rows)][0], [cell.strip() for cell in cells]))
    return rows


def _cells(path, numbered, separator, quote):
    return _rows(path, [numbered], separator, quote)[0][1]


def read_table(path):
    """The :class:`Table` of the file at ``path``; raises MeasurementError naming the line."""
    lines = [(n, _unwrapped(line.strip()))
             for n, line in enumerate(_text(path).splitlines(), start=1)]
    content = [(n, line) for n, line in lines if line and not line.startswith(COMMENT)]
    if not content:
        raise MeasurementError(f"{path}: no column row and no data")
    preamble = [line for _, line in lines if line.startswith(COMMENT)]
    for i, (number_, line) in enumerate(content):
        separator, quote = _separator([text for _, text in content[i:i + 1 + _SNIFF_ROWS]])
        names = _cells(path, (number_, line), separator, quote)
        if all(is_number(c, True) for c in names):
            if len(names) < 2:
                raise MeasurementError(f"{path}: line {number_}: only one column ({line!r}); "
                                       f"expected temperature and strain columns")
            raise MeasurementError(f"{path}: line {number_}: numbers without a column row "
                                   f"before them; expected names such as "
                                   f"temperature_C,strain_percent")
        following = _cells(path, content[i + 1], separator, quote) \
            if i + 1 < len(content) else []
        if (len(names) >= 2 and len(following) == len(names)
                and sum(is_number(c, True) for c in following) >= 2):
            check_separators(path, separator, content[i + 1:])
            rows = _rows(path, content[i + 1:], separator, quote)
            return Table(preamble, names, rows, separator == ";")
        if len(names) < 2 and i + 1 < len(content) and len(following) < 2 \
                and all(is_number(c, True) for c in following):
            raise MeasurementError(f"{path}: line {number_}: only one column ({names[0]!r}); "
                                   f"expected temperature and strain columns")
        preamble.append(line)     # a "key: value" line before the column row
    raise MeasurementError(f"{path}: no column row found")
