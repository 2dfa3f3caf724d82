"""The isobaric fit with the Clausius-Clapeyron centres (``--centre-law clausius-clapeyron``):
its numpy model is the plant runtime's with the law on, it gets a known law back from
synthetic multi-stress files within its standard errors, keeps the share from --model with
fewer than three stresses, and switches it off with ``linear``."""
import json

import numpy as np
import pytest
from scipy import sparse

from sma_fmu.cli import main

from sma_fmu.identification.isobaric.centre_law import centre_gradient
from sma_fmu.identification.isobaric.centres import LinearCentres, StrainFollowingCentres
from sma_fmu.identification.isobaric.fit import prepare, residual_blocks
from sma_fmu.identification.isobaric.jacobian import file_jacobian, scalar_sensitivities
from sma_fmu.identification.isobaric.layout import Layout
from sma_fmu.identification.isobaric.starts import starts
from sma_fmu.identification.isobaric.files import read_isobaric
from sma_fmu.identification.isobaric.fit import fit_isobaric
from sma_fmu.identification.isobaric.predict import drive_plant
from sma_fmu.identification.isobaric.synthetic import (IsobaricProgramme, isobaric_table,
                                                       isobaric_text)
from sma_fmu.identification.isobaric.terms import branch_curve, slope_load
from sma_fmu.runtime.constant_load import hysteresis_centre
from sma_fmu.runtime.constant_load import slope_load as runtime_slope_load
from sma_fmu.wire.parameter_file import load_parameters

SIGMAS = 4.0        # as tests/identification/test_isobaric.py: within 4 standard errors of the truth
LAW = dict(span_ratio_0=0.3, span_ratio_sat=1.0, span_stress=80.0, cc_share_h=0.9,
           cc_share_c=0.5)


def _truth(params):
    return params.replace(a_h=70.0, b_h=120.0, a_c=48.0, b_c=100.0, nu=115.0, **LAW)


def _files(tmp_path, truth, loads):
    """One synthetic file per load [kg]: two cycles, 1500 samples, 1 K thermocouple noise."""
    out = []
    for index, load in enumerate(loads):
        columns, _ = isobaric_table(truth, load, IsobaricProgramme(
            points=1500, seed=20 + index, cycles=2, t_low=15.0, t_high=140.0, noise_K=1.0))
        path = tmp_path / f"iso_{index}.csv"
        path.write_text(isobaric_text(columns, [f"load: {load} kg"]), encoding="utf-8")
        out.append(read_isobaric(path))
    return out


def test_the_fit_model_is_the_plant_runtime_with_the_law_on(params):
    wire = params.replace(**LAW, w2=0.3, a2_h=80.0, b2_h=60.0, a2_c=58.0, b2_c=50.0,
                          nu2_h=50.0, nu2_c=60.0)
    for load in (0.03, 0.2):
        up = np.linspace(10.0, 400.0, 1951)
        length, deviation = drive_plant(wire, np.concatenate([up, up[::-1][1:]]), load)
        assert deviation < 1e-9
        heating, _, _ = branch_curve(up, load, 1, wire, wire.x0)
        cooling, _, _ = branch_curve(up[::-1][1:], load, -1, wire, wire.x0)
        np.testing.assert_allclose(length / wire.x0 - 1.0, np.concatenate([heating, cooling]),
                                   rtol=0, atol=1e-9)
        for direction in (1, -1):
            assert slope_load(load, direction, wire) == pytest.approx(
                runtime_slope_load(load, direction, wire), rel=1e-14)


def test_the_law_holds_the_centres_at_its_anchor_loads(params):
    """The unknowns are the centres at the lowest and highest load (and the heating lead
    there), whatever the shares: the runtime's centres of the wire parameters they map to
    give them back; with the shares at 0 the map is the linear law's."""
    base = params.replace(span_ratio_0=0.3, span_stress=80.0)
    loads, temperatures = (0.02, 0.1, 0.3), (10.0, 200.0)
    u = {"tau_c_lo": 51.0, "tau_c_hi": 83.0, "gap_lo": 17.0, "gap_hi": 25.0,
         "span_ratio_0": 0.3, "span_stress": 80.0}
    law = StrainFollowingCentres(loads, base, 1, temperatures, fit_shares=True)
    assert law.names[-2:] == ["cc_share_h", "cc_share_c"]
    assert law.bounds("cc_share_h") == (0.0, 1.0)
    linear = LinearCentres(loads, base, 1, temperatures).parameters(u)
    at_zero = law.parameters(dict(u, cc_share_h=0.0, cc_share_c=0.0))
    for name, value in linear.items():
        assert at_zero[name] == pytest.approx(value, rel=1e-12, abs=1e-12), name
    wire = base.replace(**law.parameters(dict(u, cc_share_h=0.9, cc_share_c=0.4)))
    assert (wire.cc_share_h, wire.cc_share_c) == (0.9, 0.4)
    for load, cooling, lead in ((0.02, 51.0, 17.0), (0.3, 83.0, 25.0)):
        assert hysteresis_centre(load, -1, wire) == pytest.approx(cooling, abs=1e-10)
        assert hysteresis_centre(load, 1, wire) - hysteresis_centre(load, -1, wire) == \
            pytest.approx(lead, abs=1e-10)


def test_one_load_keeps_the_base_slopes_or_raises_both_centres_alike(params):
    """One load with shares from --model: the centres at the load are the unknowns; after
    the fit the base file's slopes stay when heating >= cooling down to no load, else both
    centres rise by the same amount from no load to the load."""
    base = params.replace(span_ratio_0=0.3, span_stress=80.0, cc_share_h=1.0, cc_share_c=0.2)
    for gap, kept in ((30.0, True), (2.0, False)):
        law = StrainFollowingCentres((0.3,), base, 1, (10.0, 200.0))
        u = {"tau_c": 60.0, "gap": gap}
        law.settle(u, "base.toml")
        wire = base.replace(**law.parameters(u))
        assert hysteresis_centre(0.3, -1, wire) == pytest.approx(60.0, abs=1e-10)
        assert hysteresis_centre(0.3, 1, wire) == pytest.approx(60.0 + gap, abs=1e-10)
        assert (law.slopes == (base.b_h, base.b_c)) is kept, law.slope_note
        assert wire.a_h >= wire.a_c
        if not kept:
            assert "raising both centres by" in law.slope_note
            assert wire.a_h - wire.a_c == pytest.approx(gap, abs=1e-10)


def test_the_analytic_jacobian_follows_the_law(tmp_path, params):
    """The physical columns (the shares and the stress law among them) of the sparse
    Jacobian with the strain-following centres, shares inside their bounds, against central
    differences of the whole residual."""
    truth = _truth(params)
    files = [prepare(data, i) for i, data in enumerate(_files(tmp_path, truth, (0.02, 0.1, 0.3)))]
    layout = Layout(files, params, True, False, False, False, 1, [0.02, 0.1, 0.3], "shared",
                    "clausius-clapeyron")
    assert {"cc_share_h", "cc_share_c", "span_stress"} <= set(layout.phys)
    vector, _, _ = starts(files, layout, params)
    vector[layout.phys.index("cc_share_h")] = 0.7
    vector[layout.phys.index("cc_share_c")] = 0.3
    sensitivities = scalar_sensitivities(vector, layout, [f.data.load for f in files])
    analytic = sparse.vstack([b for f in files
                              for b in file_jacobian(vector, layout, f, sensitivities)]).toarray()
    for column in range(len(layout.phys)):
        step = 1e-6 * max(abs(vector[column]), 1e-3)
        up, down = vector.copy(), vector.copy()
        up[column] += step
        down[column] -= step
        numeric = (np.concatenate(residual_blocks(up, layout, files))
                   - np.concatenate(residual_blocks(down, layout, files))) / (2 * step)
        scale = max(np.abs(numeric).max(), 1e-12)
        assert np.abs(analytic[:, column] - numeric).max() < 1e-5 * scale, layout.phys[column]


def test_a_known_law_comes_back_within_its_standard_errors(tmp_path, params):
    truth = _truth(params)
    loads = (0.01, 0.04, 0.09, 0.16, 0.3)       # 6 to 166 MPa on the 0.15 mm wire
    fit = fit_isobaric(_files(tmp_path, truth, loads), params, lag="none",
                       centre_law="clausius-clapeyron")
    assert fit.converged
    values, errors = dict(zip(fit.names, fit.values)), dict(zip(fit.names, fit.std_errors))
    known = {"a_h": truth.a_h, "b_h": truth.b_h, "a_c": truth.a_c, "b_c": truth.b_c,
             "cc_share_h": 0.9, "cc_share_c": 0.5, "span_ratio_0": 0.3, "span_stress": 80.0}
    bounds = {"a_h": 0.3, "a_c": 0.3, "b_h": 3.0, "b_c": 3.0, "cc_share_h": 0.06,
              "cc_share_c": 0.08, "span_ratio_0": 0.002, "span_stress": 1.0}
    for name, bound in bounds.items():
        assert errors[name] < bound, (name, errors[name])
        assert abs(values[name] - known[name]) <= SIGMAS * errors[name], \
            (name, values[name], known[name], errors[name])
    # the centres at each load, from the fitted law, with the errors of centre_gradient
    for load in loads:
        for direction in (1, -1):
            gradient = centre_gradient(load, direction, fit.params, fit.names)
            error = float(np.sqrt(gradient @ fit.covariance @ gradient))
            assert 0.0 < error < 0.5
            assert abs(hysteresis_centre(load, direction, fit.params)
                       - hysteresis_centre(load, direction, truth)) <= SIGMAS * error
    # linear centres miss the true centres of the same files by many of their own errors
    linear = fit_isobaric(_files(tmp_path, truth, loads), params, lag="none")
    assert "cc_share_h" not in linear.names
    worst = max(abs(hysteresis_centre(load, direction, linear.params)
                    - hysteresis_centre(load, direction, truth))
                / np.sqrt(g @ linear.covariance @ g)
                for load in loads for direction in (1, -1)
                for g in [centre_gradient(load, direction, linear.params, linear.names)])
    print(f"linear centres: worst miss {worst:.1f} standard errors")
    assert worst > 3 * SIGMAS, worst


def test_with_two_stresses_the_share_stays_from_the_model(tmp_path, params):
    base = params.replace(**LAW)
    fit = fit_isobaric(_files(tmp_path, _truth(params), (0.05, 0.2)), base, lag="none",
                       centre_law="clausius-clapeyron")
    assert "cc_share_h" not in fit.wire_names
    assert (fit.params.cc_share_h, fit.params.cc_share_c) == (0.9, 0.5)
    linear = fit_isobaric(_files(tmp_path, _truth(params), (0.05, 0.2)), base, lag="none",
                          centre_law="linear")
    assert (linear.params.cc_share_h, linear.params.cc_share_c) == (0.0, 0.0)


def test_the_command_fits_the_law_and_writes_it(tmp_path, params, capsys):
    truth = _truth(params)
    paths = []
    for index, load in enumerate((0.01, 0.08, 0.3)):
        columns, _ = isobaric_table(truth, load, IsobaricProgramme(
            points=900, seed=40 + index, cycles=1, t_low=15.0, t_high=140.0, noise_K=0.5))
        paths.append(tmp_path / f"cli_{index}.csv")
        paths[-1].write_text(isobaric_text(columns, [f"load: {load} kg"]), encoding="utf-8")
    out = tmp_path / "fit"
    assert main(["fit", "isobaric", *map(str, paths), "--centre-law", "clausius-clapeyron",
                 "--stages", "1", "--lag", "none", "--out", str(out)]) == 0
    report = json.loads((out / "report.json").read_text(encoding="utf-8"))
    assert report["centre_law"]["option"] == "clausius-clapeyron"
    assert "fitted from 3 stresses" in report["centre_law"]["note"]
    assert {"cc_share_h", "cc_share_c"} <= set(report["parameters"])
    identified = load_parameters(out / "identified.toml")
    assert identified.cc_share_h == pytest.approx(report["parameters"]["cc_share_h"]["value"])
    for load, centres in report["hysteresis_centres_degC"].items():
        value = float(load.split()[0])
        assert centres["heating"]["value"] == pytest.approx(
            hysteresis_centre(value, 1, identified), abs=1e-9)
    assert main(["fit", "constant-load", str(paths[0]), "--centre-law", "linear",
                 "--out", str(tmp_path / "cl")]) == 2
    assert "--centre-law applies to isobaric only" in capsys.readouterr().err


def test_a_law_the_data_do_not_ask_for_is_not_kept(tmp_path, params):
    """Linear centres in the truth: the shares do not lower the cost by 1 %, so the linear
    centres stay and the stage note says why."""
    truth = _truth(params).replace(cc_share_h=0.0, cc_share_c=0.0)
    fit = fit_isobaric(_files(tmp_path, truth, (0.02, 0.1, 0.25)), params, lag="none",
                       centre_law="clausius-clapeyron")
    assert fit.converged and "cc_share_h" not in fit.wire_names
    assert (fit.params.terms.cc_share_h, fit.params.terms.cc_share_c) == (0.0, 0.0)
    assert "linear centres kept" in fit.stage_note
