"""A second stage is started by splitting the fitted stage in two halves at its quartiles,
not on the first stage's own centres (a saddle of the two-stage model, from which the fit
slid into an empty or step-like stage on filtered NiTi files at 200-400 MPa), and a first
fit that stopped at its limit does not decide the stages.

The reference: a synthetic wire with two equal stages 15 K apart, written at three loads
with little noise (as a filtered file); the fit must find both stages, their share and their
centres within their standard errors, and a strain residual at the written noise."""
import math

import numpy as np
import pytest

from sma_fmu.identification.isobaric.files import read_isobaric
from sma_fmu.identification.isobaric.fit import fit_isobaric
from sma_fmu.identification.isobaric.split import quartile_offsets
from sma_fmu.identification.isobaric.synthetic import (IsobaricProgramme, isobaric_table,
                                                       isobaric_text)
from sma_fmu.identification.isobaric.terms import branch_scalars, curve
from sma_fmu.runtime.constants import HEATING

LOADS = (0.1, 0.2, 0.3)   # kg
SHIFT_K = 15.0            # the second stage's centres below the first's
NU = 60.0                 # both stages' domain size
NOISE_STRAIN = 2e-5
PROGRAMME = IsobaricProgramme(points=600, seed=3, cycles=1, noise_K=0.05,
                              noise_strain=NOISE_STRAIN, t_low=-20.0, t_high=160.0)


def _truth(params):
    return params.replace(nu_h=NU, nu_c=NU, w2=0.5, a2_h=params.a_h - SHIFT_K, b2_h=params.b_h,
                          a2_c=params.a_c - SHIFT_K, b2_c=params.b_c, nu2_h=NU, nu2_c=NU)


def test_quartile_offsets_are_where_the_stage_passes_25_and_75_percent(parameter_set):
    params = parameter_set.params
    offset = quartile_offsets(params, 0.2)["h"]
    s = branch_scalars(params, 0.2, HEATING)
    centre = float(s.centre1_K) - 273.15
    # an independent reading: the runtime curve's own transformed share q at centre -+ offset
    q = [float(curve(np.array([centre + sign * offset]), s, 1.0)[2][0]) for sign in (-1, 1)]
    # the curve is logistic in 1/T, so symmetric in T only to first order in offset / T_c
    assert sorted(q) == pytest.approx([0.25, 0.75], abs=0.25 * offset / float(s.centre1_K))
    assert offset == pytest.approx(math.log(3.0) * float(s.centre1_K) ** 2 / float(s.energy1))


def test_two_equal_stages_are_found_from_the_split(tmp_path, parameter_set):
    params = parameter_set.params
    truth = _truth(params)
    files = []
    for load in LOADS:
        columns, _ = isobaric_table(truth, load, PROGRAMME)
        path = tmp_path / f"iso_{load}.csv"
        path.write_text(isobaric_text(columns, [f"load: {load} kg"]), encoding="utf-8")
        files.append(read_isobaric(path))
    fit = fit_isobaric(files, params, lag="none", stages=2)
    assert fit.converged and fit.stages == 2, fit.stage_note
    value = dict(zip(fit.wire_names, fit.wire_values))
    error = dict(zip(fit.wire_names, fit.wire_std_errors))
    for name in ("w2", "a_h", "a_c", "a2_h", "a2_c"):
        expected = getattr(truth.terms, name) if name in ("w2", "a2_h", "a2_c") \
            else getattr(truth, name)
        assert abs(value[name] - expected) <= 3.0 * error[name], (name, value[name], expected,
                                                                   error[name])
    # the model explains the strain down to its written noise (one stage: 2.6x)
    assert fit.residual_rms["strain"] < 1.5 * NOISE_STRAIN
