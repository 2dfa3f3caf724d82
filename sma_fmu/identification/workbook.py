"""Excel workbooks as isobaric files: each worksheet one file, named ``BOOK.xlsx#SHEET``.

Test machines and labs often keep a test series as one workbook, a sheet per stress (the
sheet's first row the column names, one row per sample below). ``BOOK.xlsx`` given alone
stands for every sheet of the book, in the book's order; ``BOOK.xlsx#SHEET`` for one sheet
(``#`` because a sheet name may hold anything but ``[]:*?/\\``, and a shell leaves a ``#``
inside a word alone). openpyxl reads the book (values as last saved, not formulas); the sheet
is then written out as CSV text and read by :mod:`sma_fmu.identification.isobaric.table`
like any other file, so a sheet obeys every rule a CSV file does. A number is written with
15 significant digits, as Excel shows it, so 0.00153653 stored as 0.0015365300000000001 reads
as typed, with its written step. Old binary ``.xls`` books and OpenDocument sheets are
refused, naming the format to save them in.
"""
import csv
import datetime
import io
from pathlib import Path

__all__ = ["SUFFIXES", "split_sheet", "expand_workbooks", "sheet_text", "file_part",
           "refuse_other_spreadsheet"]

SUFFIXES = (".xlsx", ".xlsm")
_OTHER = (".xls", ".ods", ".numbers")
_SEPARATOR = "#"


def _error(message):
    """A MeasurementError (imported here: naming a book's file part needs no numpy, so the
    command line still answers a wrong path at once)."""
    from sma_fmu.identification.measurements import MeasurementError
    return MeasurementError(message)


def split_sheet(path):
    """(book path, sheet name or None) of ``path`` when it names a workbook, else None."""
    text = str(path)
    head, mark, sheet = text.rpartition(_SEPARATOR)
    if mark and head.lower().endswith(SUFFIXES):
        return Path(head), sheet
    if text.lower().endswith(SUFFIXES):
        return Path(text), None
    return None


def file_part(path):
    """The file on disk that ``path`` names (a workbook's, without ``#SHEET``)."""
    book = split_sheet(path)
    return book[0] if book else Path(path)


def refuse_other_spreadsheet(path):
    """Raise naming the format to save in when ``path`` is a spreadsheet not read here."""
    suffix = Path(str(path)).suffix.lower()
    if suffix in _OTHER:
        raise _error(f"{path}: a {suffix} spreadsheet is not read; save it as .xlsx (each "
                     f"sheet then one file: BOOK.xlsx#SHEET) or each sheet as CSV")


def _open(book):
    try:
        import openpyxl
    except ImportError:
        raise _error(f'{book}: reading a workbook needs openpyxl: pip install '
                     f'"sma-fmu[fit]"') from None
    try:
        return openpyxl.load_workbook(book, read_only=True, data_only=True)
    except FileNotFoundError:
        raise _error(f"{book}: file not found") from None
    except Exception as error:  # openpyxl raises zipfile, KeyError, ValueError... on bad books
        raise _error(f"{book}: not a readable .xlsx/.xlsm workbook "
                     f"({type(error).__name__})") from None


def _check_sheet(book, sheet, names):
    if sheet not in names:
        listed = ", ".join(repr(name) for name in names)
        raise _error(f"{book}: no sheet {sheet!r}; the book's sheets: {listed}")


def expand_workbooks(paths):
    """``paths`` (as strings) with each bare workbook replaced by one ``BOOK#SHEET`` per sheet;
    a ``BOOK#SHEET`` is checked where it is read (:func:`sheet_text`)."""
    out = []
    for path in paths:
        book = split_sheet(path)
        if book is None or book[1] is not None:
            out.append(str(path))
            continue
        workbook = _open(book[0])
        try:
            out.extend(f"{book[0]}{_SEPARATOR}{name}" for name in workbook.sheetnames)
        finally:
            workbook.close()
    return out


def _cell(value):
    """A cell as the text a CSV file would hold."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, float):
        return format(value, ".15g")
    if isinstance(value, (datetime.datetime, datetime.date, datetime.time)):
        return value.isoformat()
    return str(value)


def sheet_text(path):
    """The CSV text (comma-separated) of the sheet ``path`` (``BOOK#SHEET``, or a book with
    one sheet) names; raises MeasurementError naming the book and the sheet."""
    book, sheet = split_sheet(path)
    workbook = _open(book)
    try:
        names = list(workbook.sheetnames)
        if sheet is None:
            if len(names) != 1:
                raise _error(f"{book}: {len(names)} sheets; name one as "
                             f"{book.name}{_SEPARATOR}SHEET")
            sheet = names[0]
        _check_sheet(book, sheet, names)
        stream = io.StringIO()
        writer = csv.writer(stream, lineterminator="\n")
        for row in workbook[sheet].iter_rows(values_only=True):
            cells = [_cell(value) for value in row]
            while cells and cells[-1] == "":
                cells.pop()
            writer.writerow(cells)
        return stream.getvalue()
    finally:
        workbook.close()
