"""``--column NEW=OLD``: a lab file's column read under another name without editing the file.
A file whose ``Strain`` column holds percent reads, so renamed, as the same file with the
column named strain_percent; what cannot be renamed is refused in one line naming it."""
import json

import numpy as np
import pytest

from cli_failure import fails
from sma_fmu.cli import main
from sma_fmu.files.package_data import shipped_file
from sma_fmu.identification.isobaric.files import read_isobaric
from sma_fmu.identification.isobaric.synthetic import IsobaricProgramme, isobaric_table

LOAD = 0.3
MODEL = str(shipped_file("models", "reference_wire.toml"))


@pytest.fixture(scope="module")
def files(parameter_set, tmp_path_factory):
    """(file with a 'Strain' column in percent, the same with it named strain_percent)."""
    programme = IsobaricProgramme(t_low=20.0, t_high=130.0, rate=10.0, cycles=2, dwell=60.0,
                                  points=1200, noise_K=0.3, noise_strain=2e-5, seed=4)
    table, _ = isobaric_table(parameter_set.params, LOAD, programme, strain_unit="percent")
    folder = tmp_path_factory.mktemp("column")
    rows = [f"{t:.3f},{e:.5f}" for t, e in zip(table["temperature_C"], table["strain_percent"])]
    out = []
    for name, header in (("lab.csv", "Temperature,Strain"),
                         ("named.csv", "Temperature,strain_percent")):
        (folder / name).write_text("\n".join([header] + rows) + "\n", encoding="utf-8")
        out.append(folder / name)
    return out


def test_a_renamed_column_reads_as_the_file_named_so(files):
    lab, named = files
    renamed = read_isobaric(lab, load=LOAD, renames=[("strain_percent", "Strain")])
    reference = read_isobaric(named, load=LOAD)
    np.testing.assert_array_equal(renamed.strain, reference.strain)
    np.testing.assert_array_equal(renamed.temperature, reference.temperature)
    assert renamed.columns["strain"] == ("Strain (as strain_percent)", "percent")


def test_the_file_as_written_names_the_option(files, capsys, tmp_path):
    fails(capsys, ["fit", "isobaric", str(files[0]), "--load", str(LOAD), "--out",
                   str(tmp_path / "fit")],
          "look like percent; name the column strain_percent (or read it so: "
          "--column strain_percent='Strain')")


def test_both_commands_take_the_option(files, tmp_path, capsys):
    out = tmp_path / "fit"
    assert main(["fit", "isobaric", str(files[0]), "--load", str(LOAD), "--column",
                 "strain_percent=Strain", "--out", str(out)]) in (0, 3)
    entry = json.loads((out / "report.json").read_text())["files"][0]
    assert "Strain (as strain_percent)" in json.dumps(entry["columns"])
    predicted = tmp_path / "predict"
    assert main(["predict", "isobaric", str(files[0]), "--load", str(LOAD), "--model", MODEL,
                 "--column", "strain_percent=Strain", "--out", str(predicted)]) == 0
    assert (predicted / "report.json").is_file()


@pytest.mark.parametrize("option, words", [
    ("strain_percent=Strian", "--column strain_percent=Strian: no column 'Strian' among "
                              "'Temperature', 'Strain'"),
    ("colour=Strain", "--column colour=Strain: 'colour' names no quantity the reader knows"),
    ("strain_percent", "argument --column: expected NEW=OLD"),
])
def test_a_rename_that_cannot_apply_is_refused(files, capsys, tmp_path, option, words):
    out = tmp_path / "fit"
    fails(capsys, ["fit", "isobaric", str(files[0]), "--load", str(LOAD), "--column", option,
                   "--out", str(out)], words)
    assert not out.exists()


def test_a_column_renamed_twice_is_refused(files, capsys, tmp_path):
    fails(capsys, ["fit", "isobaric", str(files[0]), "--load", str(LOAD), "--column",
                   "strain_percent=Strain", "--column", "strain=Strain", "--out",
                   str(tmp_path / "fit")],
          "--column strain=Strain: column 'Strain' is already read as 'strain_percent' "
          "(--column strain_percent=Strain); give one --column for it")


def test_the_hint_after_a_rename_names_the_file_s_column(files, capsys, tmp_path):
    fails(capsys, ["fit", "isobaric", str(files[0]), "--load", str(LOAD), "--column",
                   "strain=Strain", "--out", str(tmp_path / "fit")],
          "column Strain (as strain): values", "--column strain_percent='Strain')")
