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
