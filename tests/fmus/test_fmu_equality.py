"""Each FMU output, stepped with fmpy, equals the library stepper's output (1e-12)."""
import pytest

from fmu_signals import STEP, plant_load, plant_power, wide_reference as reference
from sma_fmu.fmi.driving.instance import FmuInstance
from sma_fmu.fmi.python_family.slave_support.choices import choice_code
from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.plant import PlantStepper

PLANT_REALS = ("R", "T", "x", "xi_P", "xi_M", "xi_F")
STEPS = 9000  # 9 s: three load segments, reversals inside the transformation


def _assert_plant_equal(fmu, library_outputs):
    for name, value in zip(PLANT_REALS, fmu.get_real(PLANT_REALS)):
        assert value == pytest.approx(getattr(library_outputs, name), rel=0, abs=1e-12), name
    assert fmu.get_boolean(["heating"]) == [library_outputs.heating]


@pytest.mark.parametrize("mode", ["switch", "continuous"])
def test_plant_fmu_equals_library_stepper(fmus, params, mode):
    library = PlantStepper(params, mode=mode, load=plant_load(0))
    with FmuInstance(fmus["SmaActuator"], f"plant-{mode}",
                     {"load": plant_load(0),
                      "hysteresis_mode": choice_code("hysteresis_mode", mode)}) as fmu:
        _assert_plant_equal(fmu, library.outputs)
        reversals = 0
        for k in range(STEPS):
            fmu.set_real(("P_in", "load"), (plant_power(k), plant_load(k)))
            fmu.step(k * STEP, STEP)
            heating_before = library.outputs.heating
            out = library.step(plant_power(k), plant_load(k), STEP)
            reversals += out.heating != heating_before
            if k % 7 == 0 or out.heating != heating_before:
                _assert_plant_equal(fmu, out)
        _assert_plant_equal(fmu, out)
    assert reversals >= 4  # the run exercised the direction and minor-loop state


@pytest.mark.parametrize("adapt", [True, False])
def test_feedforward_fmu_equals_library_stepper(fmus, params, adapt):
    library = FeedforwardStepper(params, adapt_to_load=adapt)
    start = {"R_ref": reference(0), "load": plant_load(0), "adapt_to_load": adapt}
    with FmuInstance(fmus["SmaFeedforward"], f"ff-{adapt}", start) as fmu:
        first = library.initial_outputs(reference(0), plant_load(0))
        assert fmu.get_real(("P_ff", "T_ref")) == pytest.approx([first.P_ff, first.T_ref], abs=1e-12)
        saturated_steps = 0
        for k in range(STEPS):
            fmu.set_real(("R_ref", "load"), (reference(k), plant_load(k)))
            fmu.step(k * STEP, STEP)
            out = library.step(reference(k), plant_load(k), STEP)
            p_ff, t_ref = fmu.get_real(("P_ff", "T_ref"))
            assert p_ff == pytest.approx(out.P_ff, rel=0, abs=1e-12)
            assert t_ref == pytest.approx(out.T_ref, rel=0, abs=1e-12)
            if k % 10 == 0:
                assert fmu.get_boolean(["saturated"]) == [out.saturated]
            saturated_steps += out.saturated
    assert 0 < saturated_steps < STEPS  # both regimes were crossed


def test_fmu_parameters_reach_the_model(fmus, params):
    """A parameter set on the FMU changes its outputs exactly as in the library."""
    changed = params.replace(a_h=60.0, T_room=20.0)
    library = PlantStepper(changed, T_start=55.0, load=0.05)
    start = {"a_h": 60.0, "T_room": 20.0, "T_start": 55.0, "load": 0.05}
    with FmuInstance(fmus["SmaActuator"], "plant-params", start) as fmu:
        _assert_plant_equal(fmu, library.outputs)
        for k in range(500):
            fmu.set_real(("P_in", "load"), (1.4, 0.05))
            fmu.step(k * STEP, STEP)
            out = library.step(1.4, 0.05, STEP)
        _assert_plant_equal(fmu, out)
