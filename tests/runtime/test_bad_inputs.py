"""Invalid arguments raise ValueError naming the argument and the value; state is kept."""
import math

import pytest

from sma_fmu.runtime.constant_length import load_temperature_slope
from sma_fmu.runtime.constant_load import constant_load_resistance
from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.phase_lag import PhaseLagFilter
from sma_fmu.runtime.pi_control import PIController
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.sensing import sense_temperature

NAN, INF = math.nan, math.inf


@pytest.mark.parametrize("temperature,load,direction,match", [
    (NAN, 0.05, "heating", r"temperature must be finite, got nan"),
    (INF, 0.05, "heating", r"temperature must be finite, got inf"),
    (-300.0, 0.05, "heating", r"temperature must be above -273.15 degC, got -300"),
    (20.0, -0.1, "heating", r"load must be >= 0, got -0.1"),
    (20.0, NAN, "heating", r"load must be finite, got nan"),
    (20.0, "heavy", "heating", r"load must be a number, got 'heavy'"),
    (20.0, 0.05, "up", r"direction must be 'heating' \(\+1\) or 'cooling' \(-1\), got 'up'"),
    (20.0, 0.05, 0, r"direction must be .* got 0"),
])
def test_resistance_rejects(params, temperature, load, direction, match):
    with pytest.raises(ValueError, match=match):
        constant_load_resistance(temperature, load, direction, params)


def test_load_beyond_positive_domain_energy_is_rejected(params):
    """With x_T > 0 the domain energy dH(f) falls with load and must stay positive."""
    stretched = params.replace(x_min=0.81)
    assert stretched.x_T > 0.0
    with pytest.raises(ValueError, match=r"load = 25.0 kg is beyond the model's range: dH\(f\)"):
        constant_load_resistance(20.0, 25.0, "heating", stretched)


@pytest.mark.parametrize("resistance,match", [
    (NAN, "resistance must be finite, got nan"),
    (-3.0, r"resistance must be > 0, got -3.0"),
    (0.0, r"resistance must be > 0, got 0.0"),
])
def test_sense_rejects(params, resistance, match):
    with pytest.raises(ValueError, match=match):
        sense_temperature(resistance, 0.05, "cooling", params)


@pytest.mark.parametrize("power,load,step,match", [
    (NAN, 0.05, 1e-3, "P_in must be finite, got nan"),
    (INF, 0.05, 1e-3, "P_in must be finite, got inf"),
    (0.5, -1e-3, 1e-3, r"load must be >= 0, got -0.001"),
    (0.5, NAN, 1e-3, "load must be finite, got nan"),
    (0.5, 0.05, 0.0, r"step_size must be > 0, got 0.0"),
    (0.5, 0.05, -1e-3, r"step_size must be > 0, got -0.001"),
    (0.5, 0.05, NAN, "step_size must be finite, got nan"),
])
def test_plant_step_rejects_and_keeps_state(params, power, load, step, match):
    plant = PlantStepper(params, load=0.05)
    plant.step(0.8, 0.05, 1e-3)
    before = plant.state()
    with pytest.raises(ValueError, match=match):
        plant.step(power, load, step)
    assert plant.state() == before
    # and the stepper goes on exactly as one that never saw the bad input
    twin = PlantStepper(params, load=0.05)
    twin.step(0.8, 0.05, 1e-3)
    assert plant.step(0.8, 0.05, 1e-3) == twin.step(0.8, 0.05, 1e-3)


def test_plant_applies_negative_power_as_zero(params):
    """The paper's rule: a power of 0 W or less is 0 W; the plant reports what it applied."""
    negative, zero = PlantStepper(params, load=0.05), PlantStepper(params, load=0.05)
    for stepper in (negative, zero):
        stepper.step(2.0, 0.05, 1e-3)
    assert negative.outputs.P == 2.0
    out = negative.step(-0.7, 0.05, 1e-3)
    assert out == zero.step(0.0, 0.05, 1e-3)
    assert out.P == 0.0 and out.T < negative.state()["temperature"] + 1.0


@pytest.mark.parametrize("reference,load,step,match", [
    (NAN, 0.05, 1e-3, "R_ref must be finite, got nan"),
    (-40.0, 0.05, 1e-3, r"R_ref must be > 0, got -40.0"),
    (42.0, -0.05, 1e-3, r"load must be >= 0, got -0.05"),
    (42.0, INF, 1e-3, "load must be finite, got inf"),
    (42.0, 0.05, 0.0, r"step_size must be > 0, got 0.0"),
])
def test_feedforward_step_rejects_and_keeps_state(params, reference, load, step, match):
    ff = FeedforwardStepper(params)
    ff.step(44.0, 0.05, 1e-3)
    before = ff.state()
    with pytest.raises(ValueError, match=match):
        ff.step(reference, load, step)
    assert ff.state() == before


@pytest.mark.parametrize("kwargs,match", [
    (dict(mode="smooth"), r"hysteresis mode must be one of switch, continuous, got 'smooth'"),
    (dict(T_start=NAN), "T_start must be finite, got nan"),
    (dict(load=-1.0), r"load must be >= 0, got -1.0"),
])
def test_plant_constructor_rejects(params, kwargs, match):
    with pytest.raises(ValueError, match=match):
        PlantStepper(params, **kwargs)


def test_control_blocks_reject_bad_gains(params):
    with pytest.raises(ValueError, match=r"beta must be > 0, got 0.0"):
        PhaseLagFilter(1.0, 0.0)
    with pytest.raises(ValueError, match=r"Kp must be >= 0, got -1"):
        PIController(-1, 1.0)
    with pytest.raises(ValueError, match=r"model_load must be >= 0, got -0.2"):
        FeedforwardStepper(params, model_load=-0.2)


@pytest.mark.parametrize("fractions,match", [
    ((0.5, 0.5, 0.5), r"xi_P \+ xi_M \+ xi_F must be 1 within 0.001, got 1.5"),
    ((0.0, 0.5, 0.5), r"xi_P must be in \(0, 1\), got 0.0"),
    ((0.4, NAN, 0.3), "xi_M must be finite, got nan"),
])
def test_constant_length_rejects(params, fractions, match):
    with pytest.raises(ValueError, match=match):
        load_temperature_slope(*fractions, params)
