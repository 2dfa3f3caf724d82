"""Reversals inside the transformation: continuous mode has no jump, switch mode jumps."""
import math

import pytest

from sma_fmu.runtime.constant_load import constant_load_resistance
from sma_fmu.runtime.constants import COOLING, HEATING
from sma_fmu.runtime.plant import PlantStepper

STEP = 1e-3  # s
LOAD = 0.05  # kg


def _oscillating_run(params, mode):
    """Power oscillating about the level that holds ~62 degC: many reversals mid-transformation."""
    plant = PlantStepper(params, T_start=62.0, mode=mode, load=LOAD)
    hold = (62.0 - params.T_room) / params.K_th
    history = [plant.outputs]
    for k in range(8000):
        power = hold * (1.0 + 0.6 * math.sin(2.0 * math.pi * 0.7 * k * STEP))
        history.append(plant.step(power, LOAD, STEP))
    return history


def _max_slope(params):
    """Largest |dR/dT| [ohm/K] of either major branch at LOAD (central differences, 0.01 K)."""
    slope = 0.0
    for direction in (HEATING, COOLING):
        for i in range(4000):
            t = 30.0 + 0.02 * i
            slope = max(slope, abs(constant_load_resistance(t + 0.005, LOAD, direction, params)
                                   - constant_load_resistance(t - 0.005, LOAD, direction, params))
                        / 0.01)
    return slope


def _reversal_steps(history):
    return [k for k in range(1, len(history)) if history[k].heating != history[k - 1].heating]


def test_continuous_mode_has_no_jump_at_reversals(params):
    history = _oscillating_run(params, "continuous")
    reversals = _reversal_steps(history)
    assert len(reversals) >= 8
    bound = 1.001 * _max_slope(params)
    for k in reversals:
        jump = abs(history[k].R - history[k - 1].R)
        assert jump <= bound * abs(history[k].T - history[k - 1].T) + 1e-12


def test_continuous_mode_is_smooth_everywhere(params):
    history = _oscillating_run(params, "continuous")
    bound = 1.001 * _max_slope(params)
    for before, after in zip(history, history[1:]):
        assert abs(after.R - before.R) <= bound * abs(after.T - before.T) + 1e-12


def test_switch_mode_jumps_at_reversals(params):
    history = _oscillating_run(params, "switch")
    reversals = _reversal_steps(history)
    assert len(reversals) >= 8
    bound = 1.001 * _max_slope(params)
    jumps = [abs(history[k].R - history[k - 1].R) for k in reversals]
    limits = [bound * abs(history[k].T - history[k - 1].T) for k in reversals]
    assert all(jump > 100.0 * limit for jump, limit in zip(jumps, limits))
    assert min(jumps) > 0.5  # ohm: the branch switch is visible


def test_switch_mode_follows_the_major_branch(params):
    history = _oscillating_run(params, "switch")
    for out in history[1::250]:
        direction = HEATING if out.heating else COOLING
        assert out.R == pytest.approx(
            constant_load_resistance(out.T, LOAD, direction, params), abs=1e-12)


def test_continuous_minor_loop_stays_inside_major_loop(params):
    history = _oscillating_run(params, "continuous")
    for out in history[::50]:
        heating_r = constant_load_resistance(out.T, LOAD, HEATING, params)
        cooling_r = constant_load_resistance(out.T, LOAD, COOLING, params)
        assert cooling_r - 1e-9 <= out.R <= heating_r + 1e-9


# ---- return-point memory: the stack of reversal points (spec section 6) ------------------

def _drive_to(plant, target, load=LOAD, rate=0.05):
    """Move the plant's temperature to ``target`` [degC] in steps of at most ``rate`` K,
    with the power that lands each step exactly (the thermal model inverted)."""
    params = plant.params
    decay = math.exp(-STEP / params.tau_th)
    sign = 1.0 if target > plant.temperature else -1.0
    while (target - plant.temperature) * sign > 1e-12:
        goal = plant.temperature + sign * min(rate, abs(target - plant.temperature))
        power = (goal - params.T_room - (plant.temperature - params.T_room) * decay) / (
            params.K_th * (1.0 - decay))
        plant.step(max(0.0, power), load, STEP)
    return plant.outputs


def test_a_closed_minor_loop_returns_to_its_start(params):
    plant = PlantStepper(params, T_start=40.0, load=LOAD)
    _drive_to(plant, 76.0)
    start = _drive_to(plant, 60.0)              # the loop starts at the minimum 60 degC
    _drive_to(plant, 70.0)
    inner = _drive_to(plant, 64.0)              # a nested loop inside it, closed too
    _drive_to(plant, 67.0)
    assert _drive_to(plant, 64.0).R == pytest.approx(inner.R, abs=1e-12)
    closed = _drive_to(plant, 60.0)
    assert abs(closed.R - start.R) < 1e-12 and abs(closed.xi_M - start.xi_M) < 1e-12
    assert start.R - inner.R > 0.3                 # the loops are not trivially flat


def test_after_a_wipe_out_the_wire_is_on_the_outer_branch(params):
    """Return-point memory: a loop closed and wiped out leaves no trace on what follows."""
    looped = PlantStepper(params, T_start=40.0, load=LOAD)
    straight = PlantStepper(params, T_start=40.0, load=LOAD)
    for plant in (looped, straight):
        _drive_to(plant, 76.0)
    _drive_to(looped, 60.0)
    _drive_to(looped, 70.0)                     # minor loop 60 -> 70 -> 60, then on down
    assert len(looped.reversals) == 2
    for temperature in (58.0, 52.0, 45.0):
        a, b = _drive_to(looped, temperature), _drive_to(straight, temperature)
        assert len(looped.reversals) == len(straight.reversals) == 1
        assert abs(a.R - b.R) < 1e-12
    assert abs(a.R - constant_load_resistance(45.0, LOAD, COOLING, params)) > 0.1  # not major
    for plant in (looped, straight):            # heating past the maximum: the stack empties
        out = _drive_to(plant, 80.0)
        assert plant.reversals == []
        assert out.R == pytest.approx(constant_load_resistance(80.0, LOAD, HEATING, params),
                                      abs=1e-12)


def test_the_memory_depth_bounds_the_stack(params):
    shallow = params.replace(memory_depth=4)
    plant = PlantStepper(shallow, T_start=40.0, load=LOAD)
    turning = [80.0, 50.0, 76.0, 54.0, 72.0, 58.0, 68.0, 61.0, 66.0]   # nested inwards
    depths = []
    for temperature in turning:
        _drive_to(plant, temperature)
        depths.append(len(plant.reversals))
    assert max(depths) == 4 and all(d <= 4 for d in depths)
    # the newest points are kept: 72, 58, 68, 61 (80/50 and 76/54 were dropped in pairs)
    assert [round(p.temperature) for p in plant.reversals] == [72, 58, 68, 61]
    deep = PlantStepper(params, T_start=40.0, load=LOAD)
    for temperature in turning:
        _drive_to(deep, temperature)
    assert len(deep.reversals) == len(turning) - 1


def test_plant_state_round_trip_keeps_the_stack(params):
    plant = PlantStepper(params, T_start=40.0, load=LOAD)
    for temperature in (78.0, 55.0, 70.0, 62.0):
        _drive_to(plant, temperature)
    saved = plant.state()
    assert len(saved["reversals"]) == 3
    expected = [plant.step(p, LOAD, STEP) for p in [3.0] * 300 + [0.0] * 300]
    fresh = PlantStepper(params, load=LOAD)
    fresh.restore(saved)
    assert [fresh.step(p, LOAD, STEP) for p in [3.0] * 300 + [0.0] * 300] == expected
    forgetful = PlantStepper(params, load=LOAD)   # without the memory the result differs
    forgetful.restore(dict(saved, reversals=[]))
    assert [forgetful.step(p, LOAD, STEP) for p in [3.0] * 300 + [0.0] * 300] != expected


@pytest.mark.parametrize("change,message", [
    ({"format": None, "reversal": [60.0, 0.5]}, "earlier sma-fmu build"),
    ({"reversals": [[60.0, 1.5]]}, r"reversals\[0\]"),
    ({"reversals": [[60.0]]}, r"reversals\[0\] must be a \[T, xi_MF\] pair"),
    ({"reversals": [[60.0, 0.5]] * 65}, "at most 64"),
])
def test_plant_refuses_states_of_earlier_builds_and_malformed_stacks(params, change, message):
    plant = PlantStepper(params, load=LOAD)
    saved = dict(plant.state(), **change)
    before = plant.state()
    with pytest.raises(ValueError, match=message):
        plant.restore(saved)
    assert plant.state() == before
