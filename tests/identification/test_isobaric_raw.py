"""A raw lab file (ASMADA's 100-cycle example, ../shared/data/real-isobaric/asmada-raw/, read
in place): the fit does not depend on the load it is told beyond the centres' offset, does
not let a lag take the hysteresis, and says when it has not converged. A 16-cycle slice keeps
these fast; the whole file's numbers (three loads, timings) are in docs/identification.md.

Where the folder is absent the tests skip naming it; under CI=true they fail.
"""
import functools
import json

import numpy as np
import pytest

from sma_fmu.cli import main
from sma_fmu.identification.isobaric import runner
from sma_fmu.identification.isobaric.cycles import parse_cycles
from sma_fmu.identification.isobaric.files import noise_level, read_isobaric
from sma_fmu.identification.isobaric.fit import fit_isobaric, prepare
from sma_fmu.identification.isobaric.outcome import check_inside
from sma_fmu.identification.isobaric.summary import half_strain_table
from sma_fmu.identification.measurements import MeasurementError
from real_isobaric import real_folder as _folder

SLICE = "40:55"


def _raw():
    return _folder("asmada-raw") / "isobaric_100cycles.csv"


@pytest.fixture(scope="module")
def fits(params):
    """The slice fitted at 0.1 and 1.0 kg (the file does not say its load)."""
    out = {}
    for load in (0.1, 1.0):
        data = read_isobaric(_raw(), load, params.x0, params.diameter, parse_cycles(SLICE))
        out[load] = (data, fit_isobaric([data], params, lag="auto", stages=2))
    return out


def test_the_load_it_is_told_moves_only_the_centres_offset(fits):
    centres = {}
    for load, (data, fit) in fits.items():
        assert fit.converged, fit.message
        assert fit.lag_option == "none" and "about the same rates" in fit.lag_note
        assert any("not fitted (one load)" in note for note in fit.slope_notes)
        p = fit.params
        centres[load] = (p.a_h + p.b_h * load, p.a_c + p.b_c * load)
        for key, rms in fit.residual_rms.items():
            if rms is not None:
                assert rms <= 2.0 * fit.noise[key], (load, key)
    assert np.allclose(centres[0.1], centres[1.0], atol=2.0), centres
    # heating >= cooling is held at the load, not at zero load: held there with the base
    # file's slopes (100 and 60 degC/kg), the hysteresis at 1 kg could not fall below 40 K
    assert centres[1.0][0] - centres[1.0][1] < (100.0 - 60.0) * 1.0 - 10.0


def test_the_model_s_half_strain_temperatures_are_the_data_s(fits):
    for load, (data, fit) in fits.items():
        row, = half_strain_table([data], fit)["per_file"]
        for word in ("heating", "cooling"):
            assert abs(row[f"model_{word}_degC"] - row[f"data_{word}_degC"]) <= 3.0, (load, row)


def test_the_fitted_wire_stays_near_the_thermocouple(fits, params):
    """The profile is bounded: it may not bend by tens of kelvin where the model lacks a
    shape (the cooling branch's long tail at the bottom turns)."""
    data, fit = fits[0.1]
    f = prepare(data, 0)
    own = f.profile.basis @ f.profile.factor.solve(f.profile.basis.T @ data.temperature)
    assert np.max(np.abs(fit.measured_profiles[0] - own)) < 25.0
    assert fit.residual_rms["temperature_K"] <= 2.0 * fit.noise["temperature_K"]


def test_a_fit_that_did_not_converge_exits_3_and_says_so(tmp_path, capsys, monkeypatch):
    """Three joint evaluations cannot converge: the console names the reason, the exit
    status is 3 and identified.toml's header says NOT CONVERGED."""
    monkeypatch.setattr(runner, "fit_isobaric",
                        functools.partial(fit_isobaric, max_evaluations=3))
    out = tmp_path / "fit"
    code = main(["fit", "isobaric", str(_raw()), "--cycles", "40:45", "--load", "0.1",
                 "--stages", "1", "--out", str(out)])
    captured = capsys.readouterr()
    assert code == 3
    assert "sma-fmu: the fit did not converge: the evaluation limit was reached" in captured.err
    assert "NOT CONVERGED" in captured.out
    header = (out / "identified.toml").read_text().splitlines()[:3]
    assert any("NOT CONVERGED" in line for line in header), header
    assert json.loads((out / "report.json").read_text())["solver"]["converged"] is False


def test_a_transformation_outside_the_data_is_refused_naming_it(params):
    data = read_isobaric(_raw(), 0.1, params.x0, params.diameter, parse_cycles("40:41"))
    far = params.replace(a_h=590.0, a_c=560.0)
    with pytest.raises(MeasurementError, match="heating transformation lies outside") as error:
        check_inside(far, [prepare(data, 0)])
    assert "isobaric_100cycles.csv" in str(error.value) and "600 degC" in str(error.value)
    check_inside(params.replace(a_h=110.0, a_c=95.0), [prepare(data, 0)])   # inside: no error


def test_the_strain_residual_is_split_where_it_sits(fits):
    """The parts are the verdict's residual: their rows and squares add up to its RMS, and
    their shares to 1; on this file the ends of the branches (the austenite and martensite
    ends, where no transformation moves the strain) hold more of the squares than of the
    rows, so the misfit is a shape the model lacks there, not the transformation."""
    for load, (data, fit) in fits.items():
        entry, = fit.strain_parts
        parts = [p for p in entry["parts"] if p["rows"]]
        rows = sum(p["rows"] for p in parts)
        squares = sum(p["rows"] * p["rms"] ** 2 for p in parts)
        assert np.isclose(np.sqrt(squares / rows), fit.residual_rms["strain"], rtol=1e-9)
        assert np.isclose(sum(p["share"] for p in parts), 1.0)
        assert np.isclose(sum(c["share"] for c in entry["cycles"]), 1.0)
        left_out = {c["cycle"] for c in fit.outlier_cycles}
        assert {c["cycle"] for c in entry["cycles"]} == {b.cycle for b in data.branches} - left_out
        ends = [p for p in parts if p["phase"] != "transformation"]
        assert sum(p["share"] for p in ends) > sum(p["rows"] for p in ends) / rows, load


def test_the_strain_noise_estimate_agrees_with_a_second_one():
    """The fit's strain noise (median absolute second difference) against the README's
    3.5e-5 and against the median absolute third difference, which a quadratic trend over
    three samples does not reach: a residual ratio is not made small by a large estimate."""
    data = read_isobaric(_raw(), 0.1, 0.8, 1.5e-4)
    estimate = noise_level(data.strain)
    third = np.diff(data.strain, 3)
    second = 1.4826 * np.median(np.abs(third - np.median(third))) / np.sqrt(20.0)
    assert abs(estimate / 3.5e-5 - 1.0) < 0.1, estimate
    assert abs(estimate / second - 1.0) < 0.15, (estimate, second)
