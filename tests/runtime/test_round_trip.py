"""sense(resistance(T)) = T where the resistance is not saturated, for both modes."""
import math

import pytest

from sma_fmu.runtime.constant_load import branch_constants, constant_load_fractions
from sma_fmu.runtime.constants import COOLING, HEATING
from sma_fmu.runtime.minor_loops import ReversalPoint, fractions_on_stack
from sma_fmu.runtime.phases import resistance_of
from sma_fmu.runtime.sensing import sense_temperature

TEMPERATURES = [10.0 + 0.25 * i for i in range(401)]          # 10 ... 110 degC
LOADS = [0.0, 0.0032, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3]        # kg
TOLERANCE_K = 1e-9


def _inside(xi_mf, total):
    return 1e-4 <= xi_mf / total <= 1.0 - 1e-4


@pytest.mark.parametrize("direction", [HEATING, COOLING])
@pytest.mark.parametrize("load", LOADS)
def test_major_branch_round_trip(params, load, direction):
    total = branch_constants(load, direction, params).M
    worst, checked = 0.0, 0
    for temperature in TEMPERATURES:
        fractions = constant_load_fractions(temperature, load, direction, params)
        xi_mf = 2.0 * fractions.xi_M
        sensed = sense_temperature(resistance_of(fractions, params), load, direction, params)
        if _inside(xi_mf, total):
            assert not sensed.saturated
            worst = max(worst, abs(sensed.temperature - temperature))
            checked += 1
    assert checked > 40, "the grid must cross the transformation"
    assert worst < TOLERANCE_K


@pytest.mark.parametrize("direction", [HEATING, COOLING])
@pytest.mark.parametrize("load", [0.0, 0.05, 0.3])
def test_saturation_flagged_outside_the_transformation(params, load, direction):
    constants = branch_constants(load, direction, params)
    r_hot = params.R_P + constants.xi_F_min * (params.R_F - params.R_P)
    r_cold = r_hot + constants.M * (params.R_MF - params.R_P)
    for resistance in (r_hot - 1.0, r_hot - 1e-6, r_cold + 1e-6, r_cold + 5.0):
        sensed = sense_temperature(resistance, load, direction, params)
        assert sensed.saturated
        assert math.isfinite(sensed.temperature)
    inside = sense_temperature(0.5 * (r_hot + r_cold), load, direction, params)
    assert not inside.saturated
    assert inside.temperature == pytest.approx(constants.centre, abs=1e-9)


def test_clamped_temperatures_bracket_the_transformation(params):
    hot = sense_temperature(20.0, 0.05, HEATING, params)
    cold = sense_temperature(60.0, 0.05, HEATING, params)
    centre = branch_constants(0.05, HEATING, params).centre
    assert hot.saturated and cold.saturated
    assert cold.temperature < centre < hot.temperature


@pytest.mark.parametrize("load", [0.0, 0.05, 0.25])
@pytest.mark.parametrize("reversal_temperature,direction", [(66.0, COOLING), (72.0, COOLING),
                                                            (52.0, HEATING), (58.0, HEATING)])
def test_continuous_mode_round_trip_after_reversal(params, load, reversal_temperature, direction):
    previous = -direction  # the branch the wire was on before reversing
    xi_r = 2.0 * constant_load_fractions(reversal_temperature, load, previous, params).xi_M
    reversals = [ReversalPoint(reversal_temperature, xi_r)]
    constants = branch_constants(load, direction, params)
    worst, checked = 0.0, 0
    for temperature in TEMPERATURES:
        if (temperature - reversal_temperature) * direction < 0.0:
            continue  # the minor branch only runs onwards from the reversal
        xi_mf, xi_p = fractions_on_stack(temperature, constants, direction, reversals)
        resistance = (params.R_P * xi_p + params.R_MF * xi_mf
                      + constants.xi_F_min * params.R_F)
        sensed = sense_temperature(resistance, load, direction, params, reversals=reversals)
        if _inside(xi_mf, constants.M):
            assert not sensed.saturated
            worst = max(worst, abs(sensed.temperature - temperature))
            checked += 1
    assert checked > 10
    assert worst < TOLERANCE_K


def test_round_trip_worst_error_report(params, capsys):
    """Print the worst round-trip error over the whole grid (used in the issue note)."""
    worst = 0.0
    for load in LOADS:
        for direction in (HEATING, COOLING):
            total = branch_constants(load, direction, params).M
            for temperature in TEMPERATURES:
                fractions = constant_load_fractions(temperature, load, direction, params)
                if _inside(2.0 * fractions.xi_M, total):
                    sensed = sense_temperature(
                        resistance_of(fractions, params), load, direction, params)
                    worst = max(worst, abs(sensed.temperature - temperature))
    with capsys.disabled():
        print(f"\n[round trip] worst |sense(R(T)) - T| = {worst:.3e} K")
    assert worst < TOLERANCE_K
