"""Bad isobaric input gets one named line (``sma-fmu: error: ...``, exit 2), never a traceback,
and leaves the output folder as it was: from fit and from predict alike."""
import json

import numpy as np
import pytest

from cli_failure import fails
from sma_fmu.cli import main
from sma_fmu.files.package_data import shipped_file
from sma_fmu.identification.isobaric.synthetic import IsobaricProgramme, isobaric_table

MODEL = str(shipped_file("models", "reference_wire.toml"))


def _lines(params, stress=None, separator=" ", cycles=2):
    """A whitespace-separated file with a header line and (optionally) a stress column."""
    columns, _ = isobaric_table(params, 0.15, IsobaricProgramme(cycles=cycles, points=800, seed=3),
                                strain_unit="fraction", with_time=False)
    names = ["Temperature", "Strain"] + (["Stress"] if stress is not None else [])
    rows = [separator.join(names)]
    for i, (t, e) in enumerate(zip(columns["temperature_C"], columns["strain"])):
        cells = [f"{t:.4f}", f"{e:.8f}"] + ([f"{stress[i]:.3f}"] if stress is not None else [])
        rows.append(separator.join(cells))
    return rows


def _write(tmp_path, rows, name="bad.txt"):
    path = tmp_path / name
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return str(path)


def _both(capsys, tmp_path, path, *parts):
    """fit and predict both fail with one line naming ``parts``; no output folder appears."""
    for argv in (["fit", "isobaric", path, "--out", str(tmp_path / "out")],
                 ["predict", "isobaric", path, "--model", MODEL, "--out",
                  str(tmp_path / "out")]):
        fails(capsys, argv, *parts)
        assert not (tmp_path / "out").exists()


def test_a_file_with_no_stress_or_load(tmp_path, capsys, params):
    path = _write(tmp_path, _lines(params))
    _both(capsys, tmp_path, path, path, "no load given", "--stress")


def test_a_stress_column_that_moves_more_than_ten_percent(tmp_path, capsys, params):
    stress = np.where(np.arange(800) < 400, 80.0, 95.0)
    path = _write(tmp_path, _lines(params, stress))
    _both(capsys, tmp_path, path, path, "column Stress", "80 to 95 MPa", "one load per file")


def test_a_noisy_stress_column_sets_the_load(tmp_path, capsys, params):
    stress = 83.24 + 3.0 * np.random.default_rng(1).standard_normal(800)
    path = _write(tmp_path, _lines(params, stress))
    out = tmp_path / "out"
    assert main(["predict", "isobaric", path, "--model", MODEL, "--out", str(out)]) == 0
    report = json.loads((out / "report.json").read_text())
    assert report["stress_column_MPa"] == pytest.approx(83.24, abs=0.5)
    assert report["load_kg"] == pytest.approx(0.15, rel=0.005)
    assert report["residual_rms"]["strain"] < 2e-3    # the reference wire made the file


def test_nan_rows(tmp_path, capsys, params):
    rows = _lines(params)
    rows[101] = "NaN NaN"
    path = _write(tmp_path, ["# load: 0.15 kg"] + rows)
    _both(capsys, tmp_path, path, path, "line 103", "Temperature = 'NaN' is not finite")


def test_one_branch_only(tmp_path, capsys, params):
    rows = _lines(params, cycles=1)
    path = _write(tmp_path, ["# load: 0.15 kg"] + rows[:320])
    _both(capsys, tmp_path, path, path, "a single branch", "heating")


@pytest.mark.parametrize("header, row, words", [
    ("\t", ",", ("separated by commas", "column row by tabs")),
    (" ", ",", ("separated by commas", "column row by blanks")),
    ("\t", " ", ("no tab in", "separated by tabs")),
])
def test_separators_that_mix(tmp_path, capsys, params, header, row, words):
    rows = _lines(params, separator=header)
    rows[200] = row.join(rows[200].split(header))
    path = _write(tmp_path, ["# load: 0.15 kg"] + rows)
    _both(capsys, tmp_path, path, path, "line 202", *words)


def test_two_strain_columns_that_disagree(tmp_path, capsys, params):
    rows = _lines(params)
    rows = ["Temperature Strain Strain_p"] + [
        f"{r} {100 * float(r.split()[1]) + (0.5 if k == 300 else 0.0):.6f}"
        for k, r in enumerate(rows[1:])]
    path = _write(tmp_path, ["# load: 0.15 kg"] + rows)
    _both(capsys, tmp_path, path, path, "columns Strain and Strain_p both hold strain",
          "disagree")


def test_predict_refuses_a_missing_model_and_both_loads(tmp_path, capsys, params):
    path = _write(tmp_path, ["# load: 0.15 kg"] + _lines(params))
    fails(capsys, ["predict", "isobaric", path, "--model", str(tmp_path / "none.toml"), "--out",
                   str(tmp_path / "out")], "none.toml")
    fails(capsys, ["predict", "isobaric", path, "--model", MODEL, "--stress", "80",
                   "--load", "0.1"], "not allowed with argument")
    fails(capsys, ["predict", "isobaric", path, "--model", MODEL, "--stress", "-3"],
          "--stress -3.0 MPa is outside")
    assert not (tmp_path / "out").exists()
