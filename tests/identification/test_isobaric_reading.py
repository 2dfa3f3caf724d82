"""Reading isobaric files piece by piece: quoted tables, time stamps at a resolution, a load
ramp, missing values named once; and the shared real files read as an independent reader
reads them (../shared/data/real-isobaric/; skipped where absent, failed under CI=true)."""
import csv
import math

import numpy as np
import pytest

from real_isobaric import real_folder
from sma_fmu.cli import main
from sma_fmu.files.package_data import shipped_file
from sma_fmu.identification.isobaric.columns import classify
from sma_fmu.identification.isobaric.files import read_isobaric
from sma_fmu.identification.isobaric.stress import constant_load_rows
from sma_fmu.identification.isobaric.table import read_table
from sma_fmu.identification.isobaric.tables import rows_markdown
from sma_fmu.identification.isobaric.timebase import time_seconds
from sma_fmu.identification.isobaric.synthetic import load_of_stress
from sma_fmu.identification.measurements import MeasurementError

@pytest.mark.parametrize("line", [
    'Time (h);"Temperature, (°C)";"Extension, (mm)"',                # a separator in a name
    '"""Time (h)"";""Temperature, (°C)"";""Extension, (mm)"""',       # the row quoted again
])
def test_quoted_names_with_separators_inside(tmp_path, line):
    rows = ['"0,157";"20,5";"2,4"', '"0,158";"20,6";"2,5"'] if '"""' not in line else \
        ['"0,157;20,5;2,4"', '"0,158;20,6;2,5"']
    path = tmp_path / "q.csv"
    path.write_text("\n".join(["# machine export", line] + rows) + "\n", encoding="utf-8")
    table = read_table(path)
    assert table.names == ["Time (h)", "Temperature, (°C)", "Extension, (mm)"]
    assert table.rows == [(3, ["0,157", "20,5", "2,4"]), (4, ["0,158", "20,6", "2,5"])]
    assert table.decimal_comma


def test_a_quote_left_open_names_its_line(tmp_path):
    path = tmp_path / "open.csv"
    path.write_text('temperature_C,strain\n20,0.01\n"21,0.02\n22,0.03\n', encoding="utf-8")
    with pytest.raises(MeasurementError, match="line 3: a quote opened on this line is not "
                                               "closed on it"):
        read_table(path)


def _stamps(true_s, decimals=3):
    """Hours written to ``decimals`` decimals, as a machine does."""
    texts = [f"{t / 3600.0:.{decimals}f}" for t in true_s]
    return np.array([float(t) for t in texts]), texts


def test_repeated_stamps_of_a_steady_rate_give_its_step():
    true = 565.2 + 3.0 * np.arange(2000)          # one stamp in 3.6 s: some repeat once
    values, texts = _stamps(true)
    seconds, (note,) = time_seconds("f", "Time (h)", "h", values, texts, list(range(2000)))
    np.testing.assert_allclose(np.diff(seconds), 3.0, rtol=1e-4)
    assert np.max(np.abs(seconds - true)) <= 1.8 + 1e-6       # half the resolution
    step = float(note.split("evenly spaced, ")[1].split(" s apart")[0])
    assert step == pytest.approx(3.0, rel=1e-4)


def test_repeated_stamps_of_an_uneven_rate_stay_within_the_resolution():
    true = np.concatenate([np.arange(0.0, 1000.0, 1.0), 1000.0 + np.arange(0.0, 2000.0, 2.5)])
    values, texts = _stamps(true)
    seconds, (note,) = time_seconds("f", "Time (h)", "h", values, texts, list(range(true.size)))
    assert np.diff(seconds).min() > 0
    assert np.max(np.abs(seconds - true)) <= 3.6
    assert "uneven" in note and "middle row" in note


def test_a_time_column_that_never_moves():
    values, texts = _stamps(np.full(100, 30.0))
    with pytest.raises(MeasurementError, match="Time \\(h\\) stays at 0.008 h on every row"):
        time_seconds("f", "Time (h)", "h", values, texts, list(range(100)))


def test_a_noisy_stress_without_a_ramp_keeps_every_row():
    values = 83.0 + 3.0 * np.random.default_rng(1).standard_normal(5000)
    keep, notes = constant_load_rows("Stress", values, np.arange(5000) + 2)
    assert (keep.start, keep.stop) == (0, 5000) and notes == []


def test_a_ramp_is_cut_where_the_stress_reaches_its_load():
    values = np.concatenate([np.linspace(0.0, 100.0, 50, endpoint=False),
                             100.0 + 0.5 * np.random.default_rng(2).standard_normal(2000)])
    keep, (note,) = constant_load_rows("Stress", values, np.arange(values.size) + 2)
    assert 48 <= keep.start <= 50 and keep.stop == values.size
    assert note.startswith(f"load ramp before the constant load: lines 2-{keep.start + 1} "
                           f"({keep.start} rows, Stress 0 -> ")


@pytest.mark.parametrize("header, words", [
    ("# load: 12 kg", "12 kg is above 10 kg, the most --load accepts"),
    ("# stress: 2401 MPa", "2401 MPa is above 2000 MPa, the most --stress accepts"),
])
def test_a_header_load_beyond_the_limits(tmp_path, header, words):
    path = tmp_path / "h.csv"
    path.write_text("\n".join([header, "temperature_C,strain"]
                              + [f"{20 + k % 100},{0.01 * (k % 100 < 50)}" for k in range(400)]))
    with pytest.raises(MeasurementError, match=f"header line '{header}': {words}"):
        read_isobaric(path)


def test_each_missing_value_names_its_reason_once():
    base = {"file": "a.txt", "load_kg": 0.1, "unit": "degC"}
    reason = "heating: transformation not finished before the turn (no austenite baseline)"
    rows = [dict(base, cycle=c, quantity=q, data=math.nan, data_wire=math.nan, model=90.0 + c,
                 data_note=reason, data_wire_note=reason, model_note="")
            for c in (1, 2) for q in ("A_s", "A_f")]
    rows.append(dict(base, cycle=2, quantity="M_s", data=80.0, data_wire=80.5, model=math.nan,
                     data_note="", data_wire_note="", model_note="cooling: other"))
    text = rows_markdown(rows)
    assert text.count(reason) == 1 and text.count("cooling: other") == 1
    # data, data at the wire's temperature and the difference of four rows, and the list
    assert text.count("n/a [1]") == 4 * 3 + 1 and text.count("n/a [2]") == 1 + 1 + 1
    assert "nan" not in text


def test_predict_names_why_a_tangent_temperature_is_missing(tmp_path, capsys, params):
    path = real_folder("niti-hf-karaman") / "isobaric_600MPa.txt"
    out = tmp_path / "p"
    assert main(["predict", "isobaric", str(path), "--model",
                 str(shipped_file("models", "reference_wire.toml")), "--stress", "600",
                 "--out", str(out)]) == 0
    console = capsys.readouterr().out
    assert "nan" not in console
    a_s = next(line for line in console.splitlines() if line.startswith("A_s [degC]"))
    mark = a_s.split()[2] + " " + a_s.split()[3]
    assert mark == "n/a [1]"
    assert ("n/a [1] measured: heating: transformation not finished before the turn"
            in console)


def _loadtxt(path, delimiter=None):
    with open(path, encoding="utf-8") as stream:
        rows = list(csv.reader(stream, delimiter=delimiter or ",")) if delimiter else \
            [line.split() for line in stream]
    return rows[0], np.array([[float(c) for c in row] for row in rows[1:] if row])


@pytest.mark.parametrize("stress", [50, 100, 172, 200])
def test_the_flexinol_files_read_as_written(params, stress):
    path = real_folder("flexinol-niti") / f"isobaric_{stress}MPa.txt"
    names, table = _loadtxt(path)
    data = read_isobaric(path)
    assert names == ["Temperature", "Strain", "Stress"] and data.notes == []
    np.testing.assert_array_equal(data.temperature, table[:, 0])
    np.testing.assert_array_equal(data.strain, table[:, 1])
    assert data.stress_column == np.median(table[:, 2])


@pytest.mark.parametrize("stress", [50, 600])
def test_the_nitihf_files_read_as_written(params, stress):
    path = real_folder("niti-hf-karaman") / f"isobaric_{stress}MPa.txt"
    names, table = _loadtxt(path, "\t")
    data = read_isobaric(path, load_of_stress(stress, params.diameter))
    assert names == ["Temperature", "Strain_p", "Strain"] and data.notes == []
    np.testing.assert_array_equal(data.temperature, table[:, 0])
    np.testing.assert_array_equal(data.strain, table[:, 1] / 100.0)


def test_the_asmada_file_reads_as_written():
    path = real_folder("asmada-raw") / "isobaric_100cycles.csv"
    names, table = _loadtxt(path, ",")
    data = read_isobaric(path, 1.0)
    assert names == ["temperature_C", "strain"] and data.notes == []
    np.testing.assert_array_equal(data.temperature, table[:, 0])
    np.testing.assert_array_equal(data.strain, table[:, 1])


def test_a_strain_column_in_a_length_unit_is_refused_naming_what_to_call_it(tmp_path):
    """A machine's extensometer channel named "_Strain1 (mm)" was read as a strain fraction
    and refused as 'they look like percent'."""
    rows = [f"{t},{20 + t / 100:.3f},39.4,{19.9 + 0.001 * t:.4f}" for t in range(40)]
    path = tmp_path / "export.csv"
    path.write_text("Time (s),Temperature Chamber (C),Stress (MPa),_Strain1 (mm)\n"
                    + "\n".join(rows) + "\n", encoding="utf-8")
    with pytest.raises(MeasurementError, match=r"export.csv: column '_Strain1 \(mm\)' is named "
                                               r"strain but its unit is mm, a length: name it "
                                               r"extension_mm"):
        read_isobaric(path)
    assert classify("Strain (mm/mm)") == ("strain", "fraction")
    assert classify("Strain (%)") == ("strain", "percent")
    assert classify("_Strain1 (mm)") == ("strain", "fraction")   # the reader refuses it above
