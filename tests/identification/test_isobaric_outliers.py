"""Outlier cycles are named and left out (or kept on request); an unknown that ends on a
bound is named."""
import numpy as np

from sma_fmu.identification.isobaric.files import read_isobaric
from sma_fmu.identification.isobaric.fit import fit_isobaric
from sma_fmu.identification.isobaric.synthetic import (IsobaricProgramme, isobaric_table,
                                                       isobaric_text)


def _file(tmp_path, params, name="odd.csv", **changes):
    settings = dict(t_low=20.0, t_high=115.0, rate=20.0, dwell=0.0, noise_K=4.0, cycles=12,
                    points=12 * 260, decay=0.97, residual=1e-3, seed=4, first_shift_K=8.0)
    settings.update(changes)
    columns, _ = isobaric_table(params, 0.15, IsobaricProgramme(**settings), with_time=False)
    path = tmp_path / name
    path.write_text(isobaric_text(columns, ["load: 0.15 kg"]), encoding="utf-8")
    return read_isobaric(path)


def test_a_first_cycle_unlike_the_rest_is_named_and_left_out(tmp_path, params):
    data = _file(tmp_path, params)
    fit = fit_isobaric([data], params, lag="none", widths="shared")
    assert [c["cycle"] for c in fit.outlier_cycles] == [1]
    assert fit.outlier_cycles[0]["ratio"] > 3.0 and "odd.csv cycle 1" in fit.outlier_cycles[0]["name"]
    kept = fit_isobaric([data], params, lag="none", widths="shared", outliers="keep")
    assert [c["cycle"] for c in kept.outlier_cycles] == [1]     # named, but fitted
    values = {name: dict(zip(f.names, f.values))["a_h"] for name, f in (("out", fit),
                                                                         ("kept", kept))}
    # left out, the centre is the other cycles' (the reference wire's 68 degC at no load);
    # kept, the odd cycle pulls it
    assert abs(values["out"] - params.a_h) < 0.5 * abs(values["kept"] - params.a_h), values
    assert fit.residual_rms["strain"] < kept.residual_rms["strain"]


def test_no_outlier_in_a_clean_file(tmp_path, params):
    fit = fit_isobaric([_file(tmp_path, params, first_shift_K=0.0, noise_K=1.0)], params,
                       lag="none", widths="shared")
    assert fit.outlier_cycles == []


def test_a_lag_beyond_its_guard_is_named_on_its_bound(tmp_path, params):
    """260 samples per cycle: the guard is 13 samples; a wire 60 s (27 samples) behind."""
    data = _file(tmp_path, params, first_shift_K=0.0, lag_s=60.0, noise_K=1.0)
    fit = fit_isobaric([data], params, widths="shared")
    assert any(text.startswith("lag_0 = 13 (on its upper bound") for text in fit.on_bound), \
        fit.on_bound
    assert np.isclose(fit.lags[0]["value"], 13.0)
