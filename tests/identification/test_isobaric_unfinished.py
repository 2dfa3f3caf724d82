"""A file whose branch ends before the model's transformation is done: the fit says how much
of it lies beyond the data (the model's extrapolation, which its FMUs then run)."""
import numpy as np
import pytest

from sma_fmu.identification.isobaric.cycles import Branch
from sma_fmu.identification.coverage import DONE_SHARE, share_done
from sma_fmu.identification.isobaric.summary import unfinished_note
from sma_fmu.runtime.constant_load import hysteresis_centre
from sma_fmu.runtime.constants import COOLING, HEATING

LOAD = 0.15   # kg


def _one_stage(params):
    assert params.terms.w2 == 0.0   # the reference wire: one logistic stage
    return params


@pytest.mark.parametrize("direction", [HEATING, COOLING])
def test_at_its_centre_a_one_stage_transformation_is_half_done(params, direction):
    """The logistic stage is 1/2 at its centre (closed form), on both branches."""
    centre = hysteresis_centre(LOAD, direction, _one_stage(params))
    assert share_done(centre, LOAD, direction, params) == pytest.approx(0.5, abs=1e-12)


def test_a_branch_that_stops_at_the_centre_is_named_with_half_still_to_come(params):
    centre = hysteresis_centre(LOAD, HEATING, _one_stage(params))
    temperature = np.linspace(centre - 60.0, centre, 121)
    branch = Branch(start=0, stop=temperature.size, direction=HEATING, cycle=1, level=0,
                    complete=True)
    note = unfinished_note(temperature, [branch], LOAD, HEATING, params)
    assert note.startswith("heating: the data end at") and "50 % of the model's" in note


@pytest.mark.parametrize("direction", [HEATING, COOLING])
def test_a_branch_that_runs_through_its_transformation_has_no_note(params, direction):
    centre = hysteresis_centre(LOAD, direction, _one_stage(params))
    temperature = np.linspace(centre - 80.0, centre + 80.0, 161)[::direction]
    branch = Branch(start=0, stop=temperature.size, direction=direction, cycle=1, level=0,
                    complete=True)
    far_end = temperature[-1]
    assert share_done(far_end, LOAD, direction, params) >= DONE_SHARE
    assert unfinished_note(temperature, [branch], LOAD, direction, params) == ""
