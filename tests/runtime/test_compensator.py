"""The compensator's inverses: minor-loop round trip against the plant, clamping, load changes."""
import math
import random

import pytest

from sma_fmu.runtime.constant_load import branch_constants, hysteresis_centre
from sma_fmu.runtime.constants import COOLING, HEATING, KELVIN_OFFSET
from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.minor_loops import fractions_on_stack
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.reachable_band import reachable_band
from sma_fmu.runtime.sensing import sense_temperature

STEP = 1e-3                    # s
TOLERANCE_K = 1e-9
LOADS = [0.0, 0.05, 0.15, 0.25]  # kg


def _power_to(params, temperature, target):
    """Power [W] that takes the wire from ``temperature`` to ``target`` [degC] in one step."""
    decay = math.exp(-STEP / params.tau_th)
    return max(0.0, (target - params.T_room - (temperature - params.T_room) * decay)
               / (params.K_th * (1.0 - decay)))


def _reversal_run(params, seed, loads, loops=6):
    """Drive the continuous-mode plant through random reversals inside the transformation.

    Turning points are drawn within 10 K of the hysteresis centres, so nested minor loops
    of every size occur, in both directions, and loops close and are wiped out.
    ``loads(direction)`` gives the load of each monotone run. Yields (plant outputs, load,
    plant) after every step.
    """
    rng = random.Random(seed)
    first = loads(COOLING)
    hot, cold = hysteresis_centre(first, HEATING, params), hysteresis_centre(first, COOLING, params)
    plant = PlantStepper(params, T_start=cold - 15.0, mode="continuous", load=first)
    bottom = plant.temperature
    for _ in range(loops):
        top = rng.uniform(max(bottom + 0.5, hot - 8.0), hot + 10.0)
        bottom = rng.uniform(cold - 10.0, top - 0.5)
        for goal, sign in ((top, HEATING), (bottom, COOLING)):
            load, rate = loads(sign), rng.uniform(10.0, 40.0) * STEP  # K per step
            while (goal - plant.temperature) * sign > 1e-9:
                target = plant.temperature + sign * min(rate, abs(goal - plant.temperature))
                yield plant.step(_power_to(params, plant.temperature, target), load, STEP), load, plant


def _round_trip(params, run, same_memory_only=False):
    """Worst |T_ref - T| [K] where the plant's branch is not saturated, and how many were checked.

    ``same_memory_only``: check only samples where the compensator's direction and stack
    are the plant's (reversal points compared to 1e-9).
    """
    compensator = FeedforwardStepper(params, inverse="minor-loop")
    worst, checked, directions, totals = 0.0, 0, set(), {}
    for out, load, plant in run:
        sensed = compensator.step(out.R, load, STEP)
        if same_memory_only and not _same_memory(compensator, plant):
            continue
        if load not in totals:
            totals[load] = branch_constants(load, HEATING, params).M
        total = totals[load]
        if 1e-4 <= 2.0 * out.xi_M / total <= 1.0 - 1e-4:
            assert not sensed.saturated
            worst = max(worst, abs(sensed.T_ref - out.T))
            checked += 1
            directions.add(out.heating)
    assert directions == {True, False}
    return worst, checked


def _same_memory(compensator, plant):
    return compensator.direction == plant.direction and len(compensator.reversals) == len(
        plant.reversals) and all(abs(a.temperature - b.temperature) <= 1e-9 for a, b in zip(
            compensator.reversals, plant.reversals))


@pytest.mark.parametrize("seed", [1, 2])
@pytest.mark.parametrize("load", LOADS)
def test_minor_loop_inverse_round_trip_along_random_reversals(params, seed, load):
    worst, checked = _round_trip(params, _reversal_run(params, seed, lambda direction: load))
    assert checked > 2000
    assert worst < TOLERANCE_K


@pytest.mark.parametrize("seed", [4, 5])
def test_minor_loop_inverse_round_trip_across_load_changes(params, seed):
    """Loads change between runs (the plant re-evaluates its branch at the new load).

    d_ref comes from the reference, so a load change must not reverse R: the load falls
    while heating and rises while cooling, which moves R the way the temperature does.
    But on a minor branch a load step moves xi_MF as well (the branch is re-evaluated at
    the new load), so R can move against the temperature for one sample; d_ref, taken
    from R, then differs from the plant's direction and the compensator stores a reversal
    the plant does not have. Where the two memories agree, the inverse is exact; they must
    agree on most samples.
    """
    rng = random.Random(seed)
    state = {"load": 0.1}

    def loads(direction):
        state["load"] = max(0.0, min(0.3, state["load"] - direction * rng.uniform(0.0, 0.05)))
        return state["load"]

    run = _reversal_run(params, seed, loads, loops=8)
    worst, checked = _round_trip(params, run, same_memory_only=True)
    assert checked > 2000
    assert worst < TOLERANCE_K


def test_a_loop_wiped_out_after_a_load_change_continues_on_the_new_loads_outer_branch(params):
    """The spec's rule, checked against the closed form: after the wipe the wire is on the
    branch of the remaining top point at the new load, not at the stored point B."""
    plant = PlantStepper(params, T_start=40.0, mode="continuous", load=0.05)
    for target in (80.0, 55.0, 70.0):          # max 80, min 55, heating towards 70
        sign = HEATING if target > plant.temperature else COOLING
        while (target - plant.temperature) * sign > 1e-9:
            goal = plant.temperature + sign * min(0.05, abs(target - plant.temperature))
            plant.step(_power_to(params, plant.temperature, goal), 0.05, STEP)
    assert [round(p.temperature) for p in plant.reversals] == [80, 55]
    heavy = 0.15
    plant.step(_power_to(params, plant.temperature, plant.temperature - 0.05), heavy, STEP)
    assert [round(p.temperature) for p in plant.reversals] == [80, 55, 70]
    while plant.temperature > 54.0:            # cooling past B = (55 degC, ...) at a new load
        plant.step(_power_to(params, plant.temperature, plant.temperature - 0.05), heavy, STEP)
    assert [round(p.temperature) for p in plant.reversals] == [80]
    constants = branch_constants(heavy, COOLING, params)
    xi_mf, _ = fractions_on_stack(plant.temperature, constants, COOLING, plant.reversals)
    assert plant.xi_MF == pytest.approx(xi_mf, abs=1e-15)


def test_major_inverse_is_the_default_and_ignores_reversals(params):
    """The paper's compensator: the major branch of d_ref, whatever came before."""
    major, explicit = FeedforwardStepper(params), FeedforwardStepper(params, inverse="major")
    minor = FeedforwardStepper(params, inverse="minor-loop")
    references = [45.0, 44.0, 40.0, 38.0, 39.0, 42.0, 41.0]
    differs = False
    for k, reference in enumerate(references):
        out = major.step(reference, 0.05, STEP)
        assert explicit.step(reference, 0.05, STEP) == out
        direction = major.direction
        assert out.T_ref == sense_temperature(reference, 0.05, direction, params).temperature
        differs |= abs(minor.step(reference, 0.05, STEP).T_ref - out.T_ref) > 0.1
    assert differs  # after the reversals the minor-loop inverse is on another branch


def _edge_temperature(constants, fraction_mf, fraction_p):
    """Major-branch temperature [degC] where (xi_MF, xi_P) = the given fractions (closed form)."""
    inverse_kelvin = (constants.inv_centre_K
                      - math.log(fraction_p / fraction_mf) / constants.energy_over_kB)
    return 1.0 / inverse_kelvin - KELVIN_OFFSET


@pytest.mark.parametrize("inverse", ["major", "minor-loop"])
@pytest.mark.parametrize("load", [0.0032, 0.15])
def test_reference_outside_the_band_is_clamped_to_the_edge(params, inverse, load):
    """Below R_hot while heating: the hot edge; above R_cold while cooling: the cold edge."""
    band = reachable_band(load, params)
    delta = params.saturation_margin
    compensator = FeedforwardStepper(params, inverse=inverse)
    heating = branch_constants(load, HEATING, params)
    cooling = branch_constants(load, COOLING, params)
    out = compensator.step(band.hot - 0.5, load, STEP)  # first sample: heating, major branch
    assert out.saturated
    assert out.T_ref == pytest.approx(
        _edge_temperature(heating, delta * heating.M, (1 - delta) * heating.M), abs=1e-9)
    inside = compensator.step(0.5 * (band.hot + band.cold), load, STEP)  # rising: cooling
    assert not inside.saturated
    above = compensator.step(band.cold + 0.5, load, STEP)
    assert above.saturated
    if inverse == "major":
        expected = _edge_temperature(cooling, (1 - delta) * cooling.M, delta * cooling.M)
        assert above.T_ref == pytest.approx(expected, abs=1e-9)
    else:  # the cold edge of the minor branch the compensator is on
        xi_mf, xi_p = fractions_on_stack(above.T_ref, cooling, COOLING, compensator.reversals)
        assert xi_p == pytest.approx(delta * cooling.M, rel=1e-6)


def test_minor_branch_after_a_load_change_is_inverted_on_its_continuation(params):
    """A reversal near the cold end, then a heavier load: the target lies behind A.

    The branch of the top point, re-evaluated at the new load, is inverted on its own
    continuation (the same affine map of the major branch, our choice where the spec is
    silent): the plant's branch formula at T_ref gives the target back, unsaturated; a
    reference beyond the band saturates at the cold edge of the major branch.
    """
    compensator = FeedforwardStepper(params, inverse="minor-loop")
    light, heavy = 0.0, 0.25
    light_band = reachable_band(light, params)
    compensator.step(light_band.cold - 1.0, light, STEP)          # heating
    compensator.step(light_band.cold - 0.2, light, STEP)          # rising: cooling, reversal
    compensator.step(light_band.cold - 0.05, light, STEP)         # cooling on, nearly cold
    inside = compensator.step(light_band.cold - 0.06, light, STEP)  # falling: heating, reversal
    assert not inside.saturated and compensator.direction == HEATING
    assert len(compensator.reversals) == 2
    heavy_band = reachable_band(heavy, params)
    constants = branch_constants(heavy, HEATING, params)
    reference = heavy_band.cold - 1e-3
    out = compensator.step(reference, heavy, STEP)     # still falling, heavier load
    assert compensator.direction == HEATING and not out.saturated
    target = (reference - heavy_band.hot) / (params.R_MF - params.R_P)
    xi_mf, _ = fractions_on_stack(out.T_ref, constants, HEATING, compensator.reversals)
    assert xi_mf == pytest.approx(target, abs=1e-9)
    beyond = compensator.step(heavy_band.hot - 0.5, heavy, STEP)    # below the band: hot edge
    assert beyond.saturated and beyond.T_ref > out.T_ref


def test_reversal_point_is_the_state_assumed_at_the_previous_sample(params):
    compensator = FeedforwardStepper(params, inverse="minor-loop")
    first = compensator.step(40.0, 0.05, STEP)
    second = compensator.step(38.0, 0.05, STEP)
    assert compensator.reversals == []                        # still heating, major branch
    compensator.step(39.0, 0.05, STEP)                        # rising: reversal
    constants = branch_constants(0.05, HEATING, params)
    band = reachable_band(0.05, params)
    assert compensator.reversals[-1].temperature == second.T_ref != first.T_ref
    assert compensator.reversals[-1].xi_MF == pytest.approx(
        (38.0 - band.hot) / (params.R_MF - params.R_P), abs=1e-15)
    assert compensator.reversals[-1].xi_MF < constants.M


def test_state_restores_the_minor_loop_memory(params):
    compensator = FeedforwardStepper(params, inverse="minor-loop")
    for reference in (44.0, 40.0, 42.0, 41.0):
        compensator.step(reference, 0.05, STEP)
    saved = compensator.state()
    expected = [compensator.step(r, 0.05, STEP) for r in (43.0, 45.0, 39.0)]
    fresh = FeedforwardStepper(params, inverse="minor-loop")
    fresh.restore(saved)
    assert [fresh.step(r, 0.05, STEP) for r in (43.0, 45.0, 39.0)] == expected


def test_unknown_inverse_is_rejected(params):
    with pytest.raises(ValueError, match=r"inverse must be one of major, minor-loop, got 'minor'"):
        FeedforwardStepper(params, inverse="minor")
