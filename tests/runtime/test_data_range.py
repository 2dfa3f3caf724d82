"""The data range of a wire (validity.T_data_min ... stress_data_max, optional): the stress
bounds as loads, one warning per stepper the first time a run lies outside the range (the
start included), none without a range, and a parameter file that keeps it."""
import math

import pytest

from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.reachable_band import reachable_band
from sma_fmu.runtime.validity import DATA_RANGE_NOTE
from sma_fmu.wire.parameter_file import load_parameter_set, write_parameter_file

RANGE = dict(T_data_min=30.0, T_data_max=140.0, stress_data_min=50.0, stress_data_max=200.0)


def _data(warning):
    return warning is not None and DATA_RANGE_NOTE in warning


def test_the_stress_bounds_are_loads_on_the_wire(params):
    wire = params.replace(**RANGE)
    # 200 MPa on a 0.15 mm wire: 200e6 Pa x 1.7671e-8 m2 = 3.5343 N = 0.36040 kg-force
    assert wire.load_data_max == pytest.approx(0.36040, abs=5e-5)
    assert wire.load_data_min == pytest.approx(0.36040 / 4, abs=5e-5)
    assert wire.data_range and not params.data_range
    assert params.load_data_min is None and params.T_data_max is None


def test_the_plant_warns_once_from_the_start(params):
    wire = params.replace(**RANGE)   # T_room = 10 degC lies below the data
    plant = PlantStepper(wire, load=0.15)
    assert plant.warning == (f"T = 10 degC is below validity.T_data_min = 30 degC: "
                             f"{DATA_RANGE_NOTE}")
    seen = []
    for power, load in [(2.0, 0.15)] * 400 + [(0.0, 0.5)] * 400 + [(6.0, 0.02)] * 400:
        plant.step(power, load, 0.01)
        seen.append(plant.warning)
    assert not any(_data(w) for w in seen)          # the one warning was the start's
    assert plant.temperature > 140.0               # though the run left the range again


def test_the_plant_warns_at_the_first_step_outside(params):
    wire = params.replace(T_data_max=60.0)          # one bound alone
    plant = PlantStepper(wire, load=0.1)
    assert plant.warning is None
    found = []
    for step in range(600):
        plant.step(3.0, 0.1, 0.01)           # steady state 10 + 25 K/W x 3 W = 85 degC
        if _data(plant.warning):
            found.append((step, plant.temperature, plant.warning))
    assert len(found) == 1
    step, temperature, text = found[0]
    assert temperature > 60.0 and text.startswith(f"T = {temperature:.6g} degC is above "
                                                  "validity.T_data_max = 60 degC")


def test_the_compensator_warns_once_about_a_load_outside(params):
    wire = params.replace(stress_data_min=50.0, stress_data_max=200.0)
    stepper = FeedforwardStepper(wire)
    band = reachable_band(0.15, wire)
    middle = 0.5 * (band.hot + band.cold)
    warnings = [stepper.step(middle, load, 1e-3) and stepper.warning
                for load in [0.15] * 5 + [0.02] * 5 + [0.5] * 5]
    found = [w for w in warnings if _data(w)]
    assert found == [f"load = 0.02 kg is below {wire.load_data_min:.4g} kg (validity."
                     f"stress_data_min = 50 MPa on a 0.15 mm wire): {DATA_RANGE_NOTE}"]


def test_without_a_range_the_steppers_warn_as_before(params):
    """The reference wire: the validity warnings only (T_max, stress_max), never the data's."""
    plant, stepper = PlantStepper(params, load=0.0), FeedforwardStepper(params)
    for power in [0.0, 5.0, 20.0, 0.0]:
        for _ in range(300):
            plant.step(power, 0.6, 0.01)
            stepper.step(40.0, 0.6, 0.01)
            assert not _data(plant.warning) and not _data(stepper.warning)
    assert plant.temperature > params.T_room


def test_a_parameter_file_keeps_the_range(tmp_path, parameter_set):
    wire = parameter_set.params.replace(**RANGE)
    path = tmp_path / "ranged.toml"
    write_parameter_file(path, wire, "ranged", "a wire with a data range", parameter_set.meanings)
    again = load_parameter_set(path).params
    assert {name: getattr(again, name) for name in RANGE} == RANGE
    assert math.isclose(again.load_data_max, wire.load_data_max, rel_tol=0.0)
