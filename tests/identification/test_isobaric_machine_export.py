"""A raw machine export (tests/raw_export.py: quoted rows, a load ramp, time in hours repeated
at 0.001 h, extension in mm, a stress column) reads as written, fits through the command line,
and each quirk it cannot read is refused in one line naming file, line, column and value."""
import json

import numpy as np
import pytest

from cli_failure import fails
from raw_export import PREAMBLE, RawExport, raw_export
from sma_fmu.cli import main
from sma_fmu.files.package_data import shipped_file
from sma_fmu.identification.isobaric.files import read_isobaric
from sma_fmu.identification.limits import MAX_STRESS_MPA
from sma_fmu.runtime.constant_load import hysteresis_centre
from sma_fmu.runtime.constants import COOLING, HEATING

MODEL = str(shipped_file("models", "reference_wire.toml"))
FIRST_DATA_LINE = len(PREAMBLE) + 2


def _export(tmp_path, params, name="raw.csv", edit=None, **settings):
    text, truth = raw_export(params, RawExport(**settings))
    if edit:
        lines = text.splitlines()
        edit(lines, truth)
        text = "\n".join(lines) + "\n"
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path, truth


def _floats(cells):
    return np.array([float(c) for c in cells])


@pytest.mark.parametrize("quoting", ["rows", "cells", "none"])
def test_a_raw_export_reads_as_written(tmp_path, params, quoting):
    path, truth = _export(tmp_path, params, quoting=quoting)
    data = read_isobaric(path)
    assert data.columns == {"time": ("Time (h)", "h"), "temperature": ("Temperature (°C)", "C"),
                            "extension": ("Extension (mm)", "mm"),
                            "stress": ("Stress (MPa)", "MPa")}
    ramp, reference, time = data.notes
    # the ramp (lines 7-126, the stress 0.5 -> 170 MPa) is left out: all of it or all but
    # its last row or two, already within 1 % of the load
    first, last = (int(v) for v in ramp.split("lines ")[1].split(" ")[0].split("-"))
    assert ramp.startswith("load ramp before the constant load") and first == FIRST_DATA_LINE
    assert truth["first_line"] - 3 <= last < truth["first_line"]
    rows = truth["rows"]
    n = len(rows["Time (h)"])      # the constant-load rows: the file's cells, exactly
    assert data.strain.size == truth["last_line"] - last == n + truth["first_line"] - 1 - last
    np.testing.assert_array_equal(data.temperature[-n:], _floats(rows["Temperature (°C)"]))
    np.testing.assert_allclose(data.strain[-n:], _floats(rows["Extension (mm)"]) / 800.0,
                               rtol=1e-13, atol=0)
    assert data.stress_column == pytest.approx(truth["stress_MPa"], abs=0.1)
    # stamps at 0.001 h repeat about 2.5 times: the rows are evenly spaced at the true step
    steps = np.diff(data.time)
    assert steps.min() > 0 and np.ptp(steps) < 1e-9 * steps.mean()
    assert steps.mean() == pytest.approx(truth["step_s"], rel=1e-3)
    stamps = 3600.0 * _floats(rows["Time (h)"])
    assert np.max(np.abs(data.time[-n:] - stamps)) <= 3.6
    assert "Time (h):" in time and "0.001 h = 3.6 s" in time and "evenly spaced" in time
    assert reference.startswith("strain = Extension (mm) / 800 mm: the reference length 0.8 m")
    assert [b.direction for b in data.branches] == [HEATING, COOLING] * 3


def test_the_unloading_at_the_end_and_a_stress_in_kpa(tmp_path, params):
    def to_kpa(lines, truth):
        lines[FIRST_DATA_LINE - 2] = lines[FIRST_DATA_LINE - 2].replace("MPa", "kPa")
        for k in range(FIRST_DATA_LINE - 1, len(lines)):
            cells = lines[k].split(",")
            cells[3] = f"{1000.0 * float(cells[3]):.1f}"
            lines[k] = ",".join(cells)

    path, truth = _export(tmp_path, params, quoting="none", unloading_rows=40, edit=to_kpa)
    data = read_isobaric(path)
    assert data.columns["stress"] == ("Stress (kPa)", "kPa")
    assert data.stress_column == pytest.approx(truth["stress_MPa"], abs=0.1)
    unloading = [n for n in data.notes if n.startswith("unloading after the constant load")]
    assert len(unloading) == 1 and "kPa" in unloading[0]
    assert f"-{truth['last_line'] + 40}" in unloading[0]      # to the file's last line


def test_the_command_line_fits_a_raw_export(tmp_path, params, capsys):
    path, truth = _export(tmp_path, params)
    out = tmp_path / "fit"
    assert main(["fit", "isobaric", str(path), "--out", str(out)]) == 0
    console = capsys.readouterr().out
    entry = json.loads((out / "report.json").read_text())["files"][0]
    assert entry["reference_length_m"] == 0.8
    assert entry["reference_length_source"] == "x0 of reference_wire.toml"
    assert len(entry["reading_notes"]) == 3
    for note in entry["reading_notes"]:
        assert f"raw.csv: {note}" in console
    report = json.loads((out / "report.json").read_text())
    load = entry["load_kg"]
    centres = report["hysteresis_centres_degC"][f"{load:g} kg"]
    for word, direction in (("heating", HEATING), ("cooling", COOLING)):
        assert abs(centres[word]["value"] - hysteresis_centre(load, direction, params)) < 1.0


def test_the_reference_length_reaches_the_reading_from_both_commands(tmp_path, params, capsys):
    path, _ = _export(tmp_path, params, gauge_m=0.5)
    out = tmp_path / "predict"
    assert main(["predict", "isobaric", str(path), "--model", MODEL, "--reference-length", "0.5",
                 "--out", str(out)]) == 0
    console = capsys.readouterr().out
    report = json.loads((out / "report.json").read_text())
    assert report["reference_length_m"] == 0.5
    assert report["reference_length_source"] == "--reference-length"
    assert "strain = Extension (mm) / 500 mm: the reference length 0.5 m" in console
    assert "differs from the model's x0 0.8 m" in console and "0.625 times the data's" in console
    data = read_isobaric(path, reference_length=0.5)
    assert np.ptp(data.strain) == pytest.approx(1.6 * np.ptp(read_isobaric(path).strain))


def _refused(capsys, tmp_path, path, *parts):
    """fit and predict both refuse in one line; the output folder keeps what it held."""
    out = tmp_path / "out"
    out.mkdir(exist_ok=True)
    (out / "kept.txt").write_text("before")
    for argv in (["fit", "isobaric", str(path), "--out", str(out)],
                 ["predict", "isobaric", str(path), "--model", MODEL, "--out", str(out)]):
        line = fails(capsys, argv, str(path), *parts)
        assert "np.float64" not in line and "Traceback" not in line
        assert sorted(p.name for p in out.iterdir()) == ["kept.txt"]
        assert (out / "kept.txt").read_text() == "before"


def test_a_stress_column_above_the_stress_limit(tmp_path, params, capsys):
    path, truth = _export(tmp_path, params, stress_column_mpa=1.2 * MAX_STRESS_MPA)
    _refused(capsys, tmp_path, path, "Stress (MPa) = 2", f"above {MAX_STRESS_MPA:g} MPa",
             "the most --stress accepts")
    fails(capsys, ["fit", "isobaric", str(path), "--stress", f"{1.2 * MAX_STRESS_MPA:g}"],
          f"--stress {1.2 * MAX_STRESS_MPA!r} MPa is outside (0, {MAX_STRESS_MPA:g}] MPa")
    line = fails(capsys, ["fit", "isobaric", str(path), "--out", str(tmp_path / "o")])
    row = int(line.split(": line ")[1].split(":")[0])
    assert truth["ramp_lines"][0] < row <= truth["first_line"]     # the first row above it


def test_a_time_stamp_that_goes_back(tmp_path, params, capsys):
    def back(lines, truth):
        k = truth["first_line"] + 500 - 1
        cells = lines[k].strip('"').split(",")
        cells[0] = "0.300"
        lines[k] = '"' + ",".join(cells) + '"'

    path, truth = _export(tmp_path, params, edit=back)
    line = truth["first_line"] + 500
    _refused(capsys, tmp_path, path, f"line {line}: Time (h) = 0.3 h is earlier than line "
                                     f"{line - 1}'s", "rows must be in time order")


def test_a_repeated_row_is_not_a_repeat_at_the_resolution(tmp_path, params, capsys):
    """Written to 1e-5 h (0.036 s) the stamps step by 0.0004 h: a stamp repeated there is a
    repeated row, not the export's resolution."""
    def repeat(lines, truth):
        k = truth["first_line"] + 200 - 1
        lines[k] = lines[k - 1]

    path, truth = _export(tmp_path, params, time_decimals=5, edit=repeat)
    line = truth["first_line"] + 200
    _refused(capsys, tmp_path, path, f"line {line}: Time (h) = ", f"repeats line {line - 1}'s",
             "(written to 1e-05 h)", "a repeated row?")


def test_text_in_a_quoted_row_names_the_unquoted_column(tmp_path, params, capsys):
    def text(lines, truth):
        k = truth["first_line"] + 10 - 1
        lines[k] = lines[k].rsplit(",", 1)[0] + ',n/a"'

    path, truth = _export(tmp_path, params, edit=text)
    _refused(capsys, tmp_path, path, f"line {truth['first_line'] + 10}: Stress (MPa) = 'n/a' "
                                     f"is not a number")
