"""The compensator with shaping "reachable" against the spec's heat balance.

m cp dT/dt = u - hc As (T - T_room) (spec section 9: K_th = 25.02 K/W, tau_th = 1.0426 s),
held over a step h: from T_k, no power (passive convection) gives the lowest T_(k+1) and
P_max the highest. The shaped T_ref never leaves that interval, where the paper's inverse
leaves it by kelvins; a plant driven by the shaped P_ff follows T_ref; a reference the wire
can follow passes unchanged.
"""
import math

import pytest

from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.plant import PlantStepper

SPEC_K_TH = 25.02      # [K/W], the spec's number
SPEC_TAU_TH = 1.0426   # [s]
STEP = 1e-3            # [s]
LOAD = 0.05            # [kg]
TOLERANCE_K = 1e-4     # the spec's numbers are rounded to four digits
MODES = {"major": "switch", "minor-loop": "continuous"}


def paper_reference(k):
    """R_ref [ohm] of the paper's load-step at step k: 41.85 + 6.05 cos(pi t)."""
    return 41.85 + 6.05 * math.cos(math.pi * k * STEP)


def one_step_interval(temperature, cap, T_room):
    """(lowest, highest) T [degC] one step of the spec's heat balance reaches from
    ``temperature`` with 0 <= u <= cap [W] (None: no upper end)."""
    decay = math.exp(-STEP / SPEC_TAU_TH)
    passive = T_room + (temperature - T_room) * decay
    return passive, math.inf if cap is None else passive + SPEC_K_TH * cap * (1.0 - decay)


def trajectory(stepper, references):
    return [stepper.step(r, LOAD, STEP) for r in references]


def test_the_spec_numbers_are_the_wire_s(params):
    assert params.K_th == pytest.approx(SPEC_K_TH, rel=2e-4)
    assert params.tau_th == pytest.approx(SPEC_TAU_TH, rel=1e-4)


@pytest.mark.parametrize("inverse", ["major", "minor-loop"])
@pytest.mark.parametrize("cap", [None, 3.0])
def test_the_shaped_reference_stays_in_what_one_step_reaches(params, inverse, cap):
    references = [paper_reference(k) for k in range(4000)]
    shaped = trajectory(FeedforwardStepper(params, inverse=inverse, shaping="reachable",
                                           power_cap=cap), references)
    paper = trajectory(FeedforwardStepper(params, inverse=inverse), references)
    previous, at_floor, at_cap = params.T_room, 0, 0
    for output in shaped:
        lowest, highest = one_step_interval(previous, cap, params.T_room)
        assert lowest - TOLERANCE_K <= output.T_ref <= highest + TOLERANCE_K
        assert 0.0 <= output.P_ff <= (math.inf if cap is None else cap)
        at_floor += output.T_ref < lowest + TOLERANCE_K and output.saturated
        at_cap += output.T_ref > highest - TOLERANCE_K
        previous = output.T_ref
    assert at_floor > 100                  # passive cooling binds after the reference turns
    assert cap is None or at_cap > 100     # so does the driver
    falls = [lowest - now.T_ref for before, now in zip(paper, paper[1:])
             for lowest in [one_step_interval(before.T_ref, None, params.T_room)[0]]]
    assert max(falls) > 0.1                # the paper's T_ref falls faster than convection


@pytest.mark.parametrize("inverse", ["major", "minor-loop"])
def test_a_plant_driven_by_the_shaped_power_follows_its_reference(params, inverse):
    references = [paper_reference(k) for k in range(3000)]
    stepper = FeedforwardStepper(params, inverse=inverse, shaping="reachable", power_cap=3.0)
    plant = PlantStepper(params, None, MODES[inverse], LOAD)
    for reference in references:
        output = stepper.step(reference, LOAD, STEP)
        assert plant.step(output.P_ff, LOAD, STEP).T == output.T_ref


def slow_references(inverse):
    """A reference the wire follows: major, falling (heating) over 20 s; minor-loop, a
    cosine of period 40 s whose reversals the minor branches make continuous."""
    if inverse == "major":
        return [46.0 - 6.0 * k / 20000 for k in range(20000)]
    return [41.85 + 4.0 * math.cos(2 * math.pi * k * STEP / 40.0) for k in range(40000)]


@pytest.mark.parametrize("inverse", ["major", "minor-loop"])
def test_a_reference_the_wire_can_follow_passes_unchanged(params, inverse):
    references = slow_references(inverse)
    shaped = FeedforwardStepper(params, inverse=inverse, shaping="reachable", power_cap=10.0)
    paper = FeedforwardStepper(params, inverse=inverse)
    plant = PlantStepper(params, None, MODES[inverse], LOAD)
    for k, reference in enumerate(references):
        expected, output = paper.step(reference, LOAD, STEP), shaped.step(reference, LOAD, STEP)
        R = plant.step(output.P_ff, LOAD, STEP).R
        if k < 2000:                      # from T_room to the reference: the driver's time
            continue
        assert output.T_ref == pytest.approx(expected.T_ref, abs=1e-9), k
        assert not output.saturated and R == pytest.approx(reference, rel=1e-9), k


def test_bad_shaping_arguments_name_themselves(params):
    with pytest.raises(ValueError, match="shaping must be one of none, reachable, got 'x'"):
        FeedforwardStepper(params, shaping="x")
    with pytest.raises(ValueError, match="power_cap"):
        FeedforwardStepper(params, shaping="reachable", power_cap=-1.0)
    with pytest.raises(ValueError, match="needs shaping 'reachable'"):
        FeedforwardStepper(params, power_cap=5.0)
