"""Isobaric thermal cycling: the vectorised model, tangent temperatures, and parameter recovery.

Tolerances of the recovery tests come from the fit's own covariance: every fitted quantity
must lie within 4 standard errors of the truth (a 4-sigma band fails by chance once in
~16,000 draws of a correct fit), and each standard error must stay below a stated absolute
bound, so a fit that became uninformative cannot pass by reporting a huge error.
"""
import numpy as np
import pytest
from scipy import sparse

from sma_fmu.identification.isobaric.fit import fit_isobaric
from sma_fmu.identification.isobaric.files import read_isobaric
from sma_fmu.identification.isobaric.model import (model_resistance, model_strain,
                                                   tangent_closed_form)
from sma_fmu.identification.isobaric.synthetic import (IsobaricProgramme, isobaric_table,
                                                       isobaric_text)
from sma_fmu.identification.transformation_temperatures import branch_tangents
from sma_fmu.runtime.constant_load import constant_load_fractions
from sma_fmu.runtime.phases import length_of, resistance_of

SIGMAS = 4.0


def _truth(params):
    """The reference wire moved: centres, width, cold length and resistances all changed.

    The M/F splits l_F - l_M and R_F - R_M stay: constant-load data cannot see them, and
    the fit keeps them from the base file.
    """
    return params.replace(a_h=71.0, a_c=49.0, nu=115.0, l_M=params.l_M + 1.2e-3,
                          l_F=params.l_F + 1.2e-3, R_P=34.0, R_M=51.5, R_F=49.5)


def _file(tmp_path, params, load, name="iso.csv", resistance=False, **programme):
    settings = {"points": 1500, "seed": 5}
    settings.update(programme)
    columns, truth = isobaric_table(params, load, IsobaricProgramme(**settings),
                                    with_resistance=resistance)
    path = tmp_path / name
    path.write_text(isobaric_text(columns, [f"load: {load} kg"]), encoding="utf-8")
    return path, truth


@pytest.mark.parametrize("direction", [1, -1])
def test_model_is_the_runtime_model(params, direction):
    truth = _truth(params)
    temperatures = np.linspace(20.0, 120.0, 41)
    strain = model_strain(temperatures, 0.12, direction, truth, 0.8)
    resistance = model_resistance(temperatures, 0.12, direction, truth)
    for t, e, r in zip(temperatures, strain, resistance):
        fractions = constant_load_fractions(float(t), 0.12, direction, truth)
        assert e == pytest.approx(length_of(fractions, truth) / 0.8 - 1.0, abs=1e-14)
        assert r == pytest.approx(resistance_of(fractions, truth), rel=1e-13)


@pytest.mark.parametrize("load", [0.05, 0.15, 0.25])
def test_tangent_temperatures_on_noise_free_data_match_the_closed_form(tmp_path, params, load):
    path, _ = _file(tmp_path, params, load, points=6000, noise_K=0.0, noise_strain=0.0,
                    noise_ohm=0.0, residual=0.0, cycles=2)
    data = read_isobaric(path)
    assert [b.direction for b in data.branches] == [1, -1, 1, -1]
    for b in data.branches:
        rows = slice(b.start, b.stop)
        found = branch_tangents(data.smoothed[rows], data.strain[rows], b.direction)
        exact = tangent_closed_form(load, b.direction, params, 0.8)
        for key in ("start", "finish", "midpoint"):
            assert found[key] == pytest.approx(exact[key], abs=0.5), (b.direction, key)
        # the tangent temperatures are not the hysteresis centre: the test can tell them apart
        assert abs(exact["start"] - exact["finish"]) > 5.0


def _check(fit, truth_of, bounds):
    values = dict(zip(fit.names, fit.values))
    errors = dict(zip(fit.names, fit.std_errors))
    for name, bound in bounds.items():
        assert errors[name] < bound, (name, errors[name], bound)
        assert abs(values[name] - truth_of[name]) <= SIGMAS * errors[name], \
            (name, values[name], truth_of[name], errors[name])


def test_single_load_recovery_with_noise_and_drift(tmp_path, params):
    truth = _truth(params)
    path, synthetic = _file(tmp_path, truth, 0.15, resistance=True)
    fit = fit_isobaric([read_isobaric(path)], params, lag="none")
    assert fit.converged
    assert 0.8 < fit.variance_factor < 1.25       # the noise estimates describe the residuals
    known = {"a_h": truth.a_h + (params.b_h - truth.b_h) * 0.15, "a_c": truth.a_c,
             "nu_h": truth.nu, "nu_c": truth.nu, "alpha_P": 0.0, "alpha_MF": 0.0,
             "l_MF": 0.5 * (truth.l_M + truth.l_F), "R_P": truth.R_P, "R_MF": truth.R_MF}
    known.update({f"offset_0_{k}": v for k, v in enumerate(synthetic["offsets"])})
    _check(fit, known, {"a_h": 0.4, "a_c": 0.4, "nu_h": 0.03 * truth.nu, "nu_c": 0.03 * truth.nu,
                        "alpha_P": 1e-5, "alpha_MF": 1e-5, "l_MF": 3e-5,
                        "R_P": 0.01, "R_MF": 0.01, "offset_0_1": 3e-5, "offset_0_2": 3e-5})


def test_two_loads_give_the_load_slopes(tmp_path, params):
    truth = _truth(params).replace(b_h=110.0, b_c=55.0)
    files = [read_isobaric(_file(tmp_path, truth, load, name=f"iso{load}.csv", seed=seed)[0])
             for load, seed in ((0.05, 11), (0.2, 12))]
    fit = fit_isobaric(files, params, lag="none")
    assert fit.converged
    known = {"a_h": truth.a_h, "b_h": truth.b_h, "a_c": truth.a_c, "b_c": truth.b_c,
             "nu_h": truth.nu, "nu_c": truth.nu, "l_MF": 0.5 * (truth.l_M + truth.l_F)}
    _check(fit, known, {"a_h": 0.5, "a_c": 0.5, "b_h": 4.0, "b_c": 4.0, "nu_h": 0.03 * truth.nu,
                        "nu_c": 0.03 * truth.nu})
    assert [n for n in fit.wire_names if n.startswith("b_")] == ["b_h", "b_c"]


def test_noise_free_recovery_is_exact(tmp_path, params):
    """Without dwells the programme is piecewise linear with kinks at the turning points, which
    the temperature profile represents exactly when the kinks fall on samples (1501 points:
    4,140 s in steps of 2.76 s, turning every 690 s); what is left is the file's rounding."""
    truth = _truth(params)
    path, _ = _file(tmp_path, truth, 0.1, noise_K=0.0, noise_strain=0.0, residual=0.0, dwell=0.0,
                    points=1501)
    fit = fit_isobaric([read_isobaric(path)], params, residual="none", lag="none")
    assert fit.params.a_c == pytest.approx(truth.a_c, abs=1e-3)
    assert fit.params.a_h == pytest.approx(truth.a_h + (truth.b_h - params.b_h) * 0.1, abs=1e-3)
    assert fit.params.terms.nu_h == pytest.approx(truth.nu, rel=1e-5)
    assert fit.params.terms.nu_c == pytest.approx(truth.nu, rel=1e-5)
    assert 0.5 * (fit.params.l_M + fit.params.l_F) == pytest.approx(
        0.5 * (truth.l_M + truth.l_F), abs=1e-8)


@pytest.mark.parametrize("stages", [1, 2])
def test_analytic_jacobian_matches_finite_differences(tmp_path, params, stages):
    """Every kind of column: physical (with a second stage too), offsets, the lag and the
    profile's knots (the wire temperature lags the profile by 4 samples, so the knots act
    through the lagged basis)."""
    from sma_fmu.identification.isobaric.fit import prepare, residual_blocks
    from sma_fmu.identification.isobaric.jacobian import file_jacobian
    from sma_fmu.identification.isobaric.layout import Layout
    from sma_fmu.identification.isobaric.starts import starts
    path, _ = _file(tmp_path, _truth(params), 0.15, resistance=True, points=400)
    f = prepare(read_isobaric(path), 0)
    layout = Layout([f], params, False, False, True, True, stages, [0.15])
    vector, _, _ = starts([f], layout, params)
    vector[layout.lags[0]] = 4.0
    analytic = sparse.vstack(file_jacobian(vector, layout, f)).toarray()
    knots = layout.knots[0]
    columns = list(range(len(layout.reported))) + [knots.start + 3, knots.start + 7, knots.stop - 2]
    for column in columns:
        step = 1e-6 * max(abs(vector[column]), 1e-3)
        up, down = vector.copy(), vector.copy()
        up[column] += step
        down[column] -= step
        numeric = (np.concatenate(residual_blocks(up, layout, [f]))
                   - np.concatenate(residual_blocks(down, layout, [f]))) / (2 * step)
        scale = max(np.abs(numeric).max(), 1e-12)
        assert np.abs(analytic[:, column] - numeric).max() < 1e-5 * scale, column
