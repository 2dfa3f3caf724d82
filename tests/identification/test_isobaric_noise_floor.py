"""The noise an isobaric verdict judges against is never below the file's quantisation: the
step its columns are written with over sqrt(12) (the RMS of a rounding error uniform on
+-step/2). The fit's weights keep the noise estimate."""
import json
import math

import numpy as np
import pytest

from sma_fmu.cli import main
from sma_fmu.identification.isobaric.files import noise_level, read_isobaric
from sma_fmu.identification.isobaric.fit import fit_isobaric
from sma_fmu.identification.isobaric.outcome import verdict
from sma_fmu.identification.isobaric.resolution import smooth_note
from sma_fmu.identification.isobaric.resolution import written_step
from sma_fmu.identification.isobaric.synthetic import (IsobaricProgramme, isobaric_table,
                                                       isobaric_text)


@pytest.mark.parametrize("texts, step", [
    (["23.4", "23.5", "24"], 0.1),
    (["308.4050000", "308.4060000"], 1e-3),       # padding zeros are not digits
    (["1.25e-05", "3e-4"], 1e-7),                 # the exponent counts
    (["0", "0.000", "12.30"], 0.1),               # a zero tells nothing
    (["30.165849999999998943"], 1e-18),           # a float written in full: no floor
])
def test_written_step_is_the_last_nonzero_digit(texts, step):
    assert written_step(texts) == pytest.approx(step, rel=1e-12)


def test_written_step_reads_a_decimal_comma():
    assert written_step(["23,45", "23,5"], decimal_comma=True) == pytest.approx(0.01)


def _file(tmp_path, params, digits, name, **programme):
    """A synthetic file at 0.1 kg, temperature and strain [%] written to ``digits`` decimals."""
    columns, _ = isobaric_table(params, 0.1, IsobaricProgramme(points=1501, seed=5, **programme))
    lines = ["# load: 0.1 kg", "time_s,temperature_C,strain_percent"]
    lines += [f"{t:.3f},{c:.{digits}f},{s:.{digits}f}" for t, c, s in
              zip(columns["time_s"], columns["temperature_C"], columns["strain_percent"])]
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_a_noise_free_file_is_judged_against_its_resolution(tmp_path, params, capsys):
    """Noise-free, written to 4 decimals: the temperature ramps 0.46 K a sample from 15 degC,
    so every value sits on a 0.01 K grid (written 15.4600); the strain is written to 1e-4 %
    (1e-6). Both estimates fall below step/sqrt(12), so the verdict judges against that floor
    and says so; the weights (the fit's sigma) stay the estimates; report.json holds both,
    the console names the floor."""
    path = _file(tmp_path, params, 4, "clean.csv", noise_K=0.0, noise_strain=0.0, residual=0.0,
                 dwell=0.0)
    cells = [line.split(",") for line in path.read_text().splitlines()[2:]]
    hundredths = np.array([float(c[1]) * 100 for c in cells])
    assert np.allclose(hundredths, np.round(hundredths), atol=1e-6)
    assert not np.allclose(hundredths / 10, np.round(hundredths / 10), atol=1e-6)
    data = read_isobaric(path)
    floor_K, floor_strain = 0.01 / math.sqrt(12.0), 1e-6 / math.sqrt(12.0)   # 1e-4 % = 1e-6
    assert data.resolution["temperature"]["step"] == pytest.approx(0.01)
    assert data.resolution["strain"]["step"] == pytest.approx(1e-6)
    fit = fit_isobaric([data], params, residual="none", lag="none")
    sigma, = fit.sigma
    assert sigma["temperature"] < floor_K and sigma["strain"] < floor_strain
    assert fit.noise_estimates["temperature_K"] == pytest.approx(sigma["temperature"])
    assert fit.noise["temperature_K"] == pytest.approx(floor_K)
    assert fit.noise["strain"] == pytest.approx(floor_strain)
    assert "floored at the file's resolution" in fit.verdict
    ratio = fit.residual_rms["strain"] / floor_strain
    assert f"{ratio:.2f}x" in fit.verdict or f"{ratio:.1f}x" in fit.verdict
    out = tmp_path / "fit"
    assert main(["fit", "isobaric", str(path), "--residual-strain", "none", "--lag", "none", "--stages", "1",
                 "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert ("clean.csv: temperature noise floored at the file's resolution: 0.01 K written, "
            "0.0029 K") in printed
    assert "clean.csv: strain noise floored at the file's resolution: 0.0001 percent written" \
        in printed
    report = json.loads((out / "report.json").read_text())
    # 0.0029 K and 2.9e-7 lie below a lab sensor's scatter: a ratio to them says little
    assert report["noise_smooth_note"].startswith("the noise judged against (temperature 0.00289 K, "
                                                  "strain 2.89e-07) is below a lab sensor's scatter")
    assert f"note: {report['noise_smooth_note']}" in printed
    entry, = report["files"]
    assert entry["noise_floors"]["temperature"] == pytest.approx(floor_K)
    assert entry["noise_estimates"]["temperature"] == pytest.approx(sigma["temperature"])
    assert report["noise_judged"]["strain"] == pytest.approx(floor_strain)
    assert report["noise_estimates"]["strain"] < floor_strain
    parts = [p for p in entry["strain_residual_parts"]["parts"] if p["rows"]]
    assert all(p["ratio"] == pytest.approx(p["rms"] / floor_strain) for p in parts)


def test_a_noisy_file_is_judged_against_its_estimate(tmp_path, params):
    """3 K and 1e-4 of noise, written to 4 decimals: the estimates are far above the floor,
    so the verdict is what it was without one."""
    data = read_isobaric(_file(tmp_path, params, 4, "noisy.csv", noise_K=3.0,
                               noise_strain=1e-4))
    assert noise_level(data.temperature) > 100 * 1e-4 / math.sqrt(12.0)
    fit = fit_isobaric([data], params, lag="none")
    assert fit.noise == fit.noise_estimates and fit.floor_notes == []
    assert fit.verdict == verdict(fit.residual_rms, fit.noise_estimates)
    assert "floored" not in fit.verdict
    assert smooth_note(fit.noise, fit.residual_rms) == ""   # a sensor's scatter: no note


def test_a_smooth_note_names_only_the_noise_below_a_sensors_scatter():
    rms = {"temperature_K": 0.67, "strain": 1.0e-4, "resistance_ohm": None}
    note = smooth_note({"temperature_K": 3.6e-7, "strain": 3.5e-5, "resistance_ohm": None}, rms)
    assert note.startswith("the noise judged against (temperature 3.6e-07 K) is below a lab "
                           "sensor's scatter (temperature 0.005 K)")
    assert "(temperature 0.67 K, strain 0.0001)" in note
    assert smooth_note({"temperature_K": 0.005, "strain": 5e-7}, rms) == ""   # at the scatter


def test_the_verdict_names_a_floored_noise():
    """A raw export written to 0.1 K: a 0.8 K residual is 27.7x the 0.1/sqrt(12) K floor, not
    129x a 0.0062 K estimate."""
    floor = 0.1 / math.sqrt(12.0)
    line = verdict({"temperature_K": 0.8, "strain": 1e-5, "resistance_ohm": None},
                   {"temperature_K": floor, "strain": 1e-5, "resistance_ohm": None},
                   {"temperature_K"})
    assert line.startswith("the model does not explain the data: temperature residual 0.8 K is "
                           f"{0.8 / floor:.1f}x its noise (floored at the file's resolution) "
                           f"{floor:.3g} K")
    assert np.isclose(0.8 / floor, 27.7, atol=0.05)


def _band(axis):
    """(half-height [data units], label) of the residual panel's band."""
    band, = [patch for patch in axis.patches if patch.get_label() and
             not patch.get_label().startswith("_")]
    corners = band.get_patch_transform().transform(band.get_path().vertices)
    return (corners[:, 1].max() - corners[:, 1].min()) / 2, band.get_label()


def test_the_residual_figure_draws_the_noise_the_verdict_judges_against(tmp_path, params):
    """The residual figure's band is the judged noise: on the noise-free file the floor
    (step/sqrt(12)), labelled so; on the noisy one the estimate."""
    from sma_fmu.identification.isobaric.figures import _residuals
    clean = read_isobaric(_file(tmp_path, params, 4, "clean.csv", noise_K=0.0, noise_strain=0.0,
                                residual=0.0, dwell=0.0))
    fit = fit_isobaric([clean], params, residual="none", lag="none")
    strain_axis, temperature_axis = _residuals([clean], fit).axes
    height, label = _band(strain_axis)
    assert height == pytest.approx(100 * 1e-6 / math.sqrt(12.0))   # the panel is in % strain
    assert label == "noise floored at the file's resolution"
    height, label = _band(temperature_axis)
    assert height == pytest.approx(0.01 / math.sqrt(12.0))
    assert label == "noise floored at the file's resolution"
    noisy = read_isobaric(_file(tmp_path, params, 4, "noisy.csv", noise_K=3.0, noise_strain=1e-4))
    fit = fit_isobaric([noisy], params, lag="none")
    strain_axis, temperature_axis = _residuals([noisy], fit).axes
    assert _band(strain_axis) == (pytest.approx(100 * fit.sigma[0]["strain"]), "noise estimate")
    assert _band(temperature_axis) == (pytest.approx(fit.sigma[0]["temperature"]),
                                       "noise estimate")
