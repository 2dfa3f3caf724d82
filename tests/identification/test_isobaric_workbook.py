"""Excel workbooks as isobaric files (sma_fmu/identification/workbook.py): a sheet reads as
the CSV file it was made from, a bare book stands for each of its sheets, and a book or
sheet that cannot be read is refused in one line naming it."""
import csv
import json

import numpy as np
import openpyxl
import pytest

from cli_failure import fails
from raw_export import RawExport, raw_export
from sma_fmu.cli import main
from sma_fmu.files.package_data import shipped_file
from sma_fmu.identification.isobaric.files import read_isobaric
from sma_fmu.identification.workbook import expand_workbooks, sheet_text


def _value(cell):
    """A CSV cell as Excel stores it after an import: a number where it is one."""
    try:
        return float(cell)
    except ValueError:
        return cell or None


def _book(path, sheets):
    """Write {sheet name: CSV text} as a workbook at ``path``; the cells as floats where
    they are numbers (each CSV line a row, a comment line a single cell)."""
    book = openpyxl.Workbook()
    book.remove(book.active)
    for name, text in sheets.items():
        sheet = book.create_sheet(name)
        for row in csv.reader(text.splitlines()):
            sheet.append([_value(cell) for cell in row] if row else [None])
    book.save(path)
    return path


def _exports(tmp_path, params, stresses):
    texts = {}
    for stress in stresses:
        text, _ = raw_export(params, RawExport(stress_mpa=stress, quoting="none", points=1200,
                                               cycles=2, time_decimals=4))
        texts[f"{stress:g}MPa"] = text
        (tmp_path / f"{stress:g}MPa.csv").write_text(text, encoding="utf-8")
    return texts


def test_a_sheet_reads_as_the_csv_file_it_was_made_from(tmp_path, params):
    texts = _exports(tmp_path, params, [170.0])
    book = _book(tmp_path / "series.xlsx", texts)
    from_csv = read_isobaric(tmp_path / "170MPa.csv")
    from_sheet = read_isobaric(f"{book}#170MPa")
    assert from_sheet.load == from_csv.load and from_sheet.stress_column == from_csv.stress_column
    for name in ("temperature", "strain", "time"):
        np.testing.assert_array_equal(getattr(from_sheet, name), getattr(from_csv, name))
    assert from_sheet.reference_length == from_csv.reference_length


def test_a_number_reads_with_the_digits_excel_shows(tmp_path):
    book = openpyxl.Workbook()
    sheet = book.active
    sheet.title = "200MPa"
    sheet.append(["Temperature", "Strain"])
    sheet.append([308.441, 0.0015365300000000001])
    sheet.append([308.443, None])
    book.save(tmp_path / "b.xlsx")
    assert sheet_text(f"{tmp_path / 'b.xlsx'}#200MPa").splitlines() == [
        "Temperature,Strain", "308.441,0.00153653", "308.443"]


def test_a_bare_book_stands_for_each_of_its_sheets(tmp_path, params, capsys):
    texts = _exports(tmp_path, params, [120.0, 200.0])
    book = _book(tmp_path / "series.xlsx", texts)
    assert expand_workbooks([str(book), str(tmp_path / "120MPa.csv")]) == [
        f"{book}#120MPa", f"{book}#200MPa", str(tmp_path / "120MPa.csv")]
    out = tmp_path / "fit"
    assert main(["fit", "isobaric", str(book), "--out", str(out)]) in (0, 3)
    files = json.loads((out / "report.json").read_text())["files"]
    assert [entry["stress_MPa"] for entry in files] == pytest.approx([120.0, 200.0], abs=0.5)
    assert "series.xlsx#200MPa" in capsys.readouterr().out


def test_a_missing_sheet_names_the_sheets_there_are(tmp_path, params, capsys):
    book = _book(tmp_path / "series.xlsx", _exports(tmp_path, params, [170.0]))
    out = tmp_path / "fit"
    fails(capsys, ["fit", "isobaric", f"{book}#150MPa", "--out", str(out)],
          "series.xlsx: no sheet '150MPa'; the book's sheets: '170MPa'")
    assert not out.exists()


def test_predict_asks_which_sheet_of_a_book_with_several(tmp_path, params, capsys):
    book = _book(tmp_path / "series.xlsx", _exports(tmp_path, params, [120.0, 200.0]))
    model = str(shipped_file("models", "reference_wire.toml"))
    fails(capsys, ["predict", "isobaric", str(book), "--model", model, "--out",
                   str(tmp_path / "p")],
          "series.xlsx: 2 sheets; name one as series.xlsx#SHEET")


@pytest.mark.parametrize("name, content, words", [
    ("broken.xlsx", b"temperature_C,strain\n20,0.01\n", "not a readable .xlsx/.xlsm workbook"),
    ("old.xls", b"\xd0\xcf\x11\xe0", "a .xls spreadsheet is not read; save it as .xlsx"),
    ("gone.xlsx", None, "gone.xlsx: file not found"),
])
def test_a_book_that_cannot_be_read_is_refused_in_one_line(tmp_path, capsys, name, content,
                                                           words):
    path = tmp_path / name
    if content is not None:
        path.write_bytes(content)
    fails(capsys, ["fit", "isobaric", str(path), "--load", "0.3", "--out",
                   str(tmp_path / "fit")], words)


def test_predict_refuses_an_old_spreadsheet_as_fit_does(tmp_path, capsys):
    path = tmp_path / "old.xls"
    path.write_bytes(b"\xd0\xcf\x11\xe0")
    model = str(shipped_file("models", "reference_wire.toml"))
    fails(capsys, ["predict", "isobaric", str(path), "--model", model, "--load", "0.3",
                   "--out", str(tmp_path / "p")], "a .xls spreadsheet is not read; save it as .xlsx")
