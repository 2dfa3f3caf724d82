"""The shared real isobaric files (../shared/data/real-isobaric/ seen from the project root):
read as they are, fitted jointly, a held-out stress predicted by the plant runtime.

The files have no licence: they are read in place, never copied into the project. Where the
folder is absent the tests skip naming it; under CI=true they fail instead.
"""
import json

import numpy as np
import pytest

from real_isobaric import real_folder
from sma_fmu.cli import main
from sma_fmu.identification.isobaric.files import read_isobaric
from sma_fmu.identification.isobaric.fit import fit_isobaric
from sma_fmu.identification.isobaric.synthetic import load_of_stress

FLEXINOL = (50, 100, 172, 200)
NITIHF = (50, 100, 200, 300, 400, 500, 600)


def _flexinol(stress):
    return real_folder("flexinol-niti") / f"isobaric_{stress}MPa.txt"


def _nitihf(stress):
    return real_folder("niti-hf-karaman") / f"isobaric_{stress}MPa.txt"


def test_the_shared_files_read_as_they_are(params):
    """Flexinol: blanks, a stress column per row (the load from its median); NiTiHf: tabs,
    the strain twice, the finer Strain_p [%] used and named."""
    flex = read_isobaric(_flexinol(172))
    assert flex.columns["stress"] == ("Stress", "MPa")
    assert flex.stress_column == pytest.approx(172.0, abs=1.0)
    assert flex.load == pytest.approx(load_of_stress(flex.stress_column, params.diameter))
    hf = read_isobaric(_nitihf(300), load_of_stress(300.0, params.diameter))
    assert hf.columns["strain"] == ("Strain_p", "percent")
    assert "strain from Strain_p" in hf.strain_note and "finer than Strain's" in hf.strain_note
    assert [b.direction for b in hf.branches if b.complete] == [-1, 1]


def test_the_shared_files_written_steps(params):
    """The written step the verdict's noise floor rests on: NiTiHf's temperature is padded to
    seven decimals (308.4050000) and its values move by the smallest difference between them;
    Flexinol writes every float in full, so its floor is nothing."""
    hf = read_isobaric(_nitihf(300), load_of_stress(300.0, params.diameter))
    levels = np.diff(np.unique(hf.temperature))
    assert hf.resolution["temperature"]["step"] == pytest.approx(levels[levels > 0].min(),
                                                                 rel=1e-6)
    assert hf.resolution["strain"]["unit"] == "percent"
    assert hf.resolution["strain"]["step"] == pytest.approx(
        hf.resolution["strain"]["written"] / 100.0)
    flex = read_isobaric(_flexinol(172))
    assert flex.resolution["temperature"]["step"] < 1e-12


@pytest.fixture(scope="module")
def flexinol_fit(tmp_path_factory, parameter_set):
    out = tmp_path_factory.mktemp("flex") / "fit"
    files = [str(_flexinol(s)) for s in FLEXINOL]
    assert main(["fit", "isobaric", *files, "--out", str(out)]) == 0   # every option its default
    return json.loads((out / "report.json").read_text()), out


def test_flexinol_four_stresses_jointly(flexinol_fit):
    """Strain residual RMS <= 5e-4 in every file; the model's half-strain temperatures move
    with stress within 10 % of the data's own slopes (0.124 and 0.134 K/MPa)."""
    report, out = flexinol_fit
    assert report["lag_choice"]["option"] == "none"     # one cycle per file: --lag auto
    assert "single complete cycle" in report["lag_choice"]["note"]
    assert report["stages"] == 2
    for entry in report["files"]:
        assert entry["residual_rms"]["strain"] <= 5e-4, entry["file"]
    slopes = report["half_strain"]["slopes_K_per_MPa"]
    assert slopes["data"]["heating"] == pytest.approx(0.124, rel=0.03)
    assert slopes["data"]["cooling"] == pytest.approx(0.134, rel=0.03)
    assert slopes["model"]["heating"] == pytest.approx(0.124, rel=0.10)
    assert slopes["model"]["cooling"] == pytest.approx(0.134, rel=0.10)
    assert report["parameters"]["a_h"]["value"] >= report["parameters"]["a_c"]["value"]
    assert report["parameters"]["a2_h"]["value"] >= report["parameters"]["a2_c"]["value"]
    assert "verdict" in report and report["on_bound"] == []
    assert (out / "identified.toml").is_file() and (out / "fit_isobaric_cycles.png").is_file()


def test_nitihf_seven_stresses_jointly(params):
    """The model's transformation strain within 10 % of the data's at every stress."""
    data = [read_isobaric(_nitihf(s), load_of_stress(s, params.diameter)) for s in NITIHF]
    fit = fit_isobaric(data, params, lag="none", stages=2)
    from sma_fmu.identification.isobaric.summary import half_strain_table
    rows = half_strain_table(data, fit)["per_file"]
    spans = [(r["data_transformation_strain"], r["model_transformation_strain"]) for r in rows]
    assert spans[0][0] < 0.01 and spans[-1][0] > 0.025      # it grows with stress
    for (measured, model), stress in zip(spans, NITIHF):
        assert model == pytest.approx(measured, rel=0.10), stress


def test_a_held_out_stress_is_predicted_by_the_plant_runtime(tmp_path):
    """Fit 50, 100 and 200 MPa, predict 172 MPa: strain RMS <= 2.5e-3, half-strain
    temperatures within 2 K on heating and on cooling."""
    fit = tmp_path / "fit"
    assert main(["fit", "isobaric", *[str(_flexinol(s)) for s in (50, 100, 200)], "--lag",
                 "none", "--out", str(fit)]) == 0
    out = tmp_path / "predict"
    assert main(["predict", "isobaric", str(_flexinol(172)), "--model",
                 str(fit / "identified.toml"), "--out", str(out)]) == 0
    report = json.loads((out / "report.json").read_text())
    assert report["residual_rms"]["strain"] <= 2.5e-3
    difference = report["transformation_temperatures"]["predicted_minus_measured"]
    assert abs(difference["half_heating"]) <= 2.0 and abs(difference["half_cooling"]) <= 2.0
    assert report["drive"]["largest_temperature_deviation_K"] < 1e-6
    assert report["stress_MPa"] == pytest.approx(172.0, abs=1.0)
    rows = np.loadtxt(out / "predicted.csv", delimiter=",", skiprows=1)
    assert rows.shape == (report["points"], 4)
    assert (out / "predict_isobaric.png").stat().st_size > 10_000


def test_a_missing_data_folder_skips_naming_it_and_fails_under_ci(monkeypatch, tmp_path):
    import real_isobaric as here
    monkeypatch.setattr(here, "REAL", tmp_path / "absent")
    monkeypatch.delenv("CI", raising=False)
    with pytest.raises(pytest.skip.Exception, match="absent"):
        here.real_folder("flexinol-niti")
    monkeypatch.setenv("CI", "true")
    with pytest.raises(pytest.fail.Exception, match="absent"):
        here.real_folder("flexinol-niti")
