"""Bad inputs to the FMUs: a discard with a logged message naming the input; nothing is lost.
Bad parameters and illegal calls: fmi2Error, a message, and the instance as it was."""
import math

import pytest

from fmu_signals import STEP
from sma_fmu.fmi.driving.instance import FmuError, FmuInstance
from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.plant import PlantStepper

DISCARD, ERROR, FATAL = 2, 3, 4


@pytest.mark.parametrize("power,load,step,message", [
    (math.nan, 0.05, STEP, "P_in must be finite, got nan"),
    (math.inf, 0.05, STEP, "P_in must be finite, got inf"),
    (0.8, -0.01, STEP, "load must be >= 0, got -0.01"),
    (0.8, math.nan, STEP, "load must be finite, got nan"),
    (1e307, 0.05, STEP, "would take the wire temperature out of the floating-point range"),
])
def test_plant_discards_bad_input_and_stays_usable(fmus, params, power, load, step, message):
    library = PlantStepper(params, load=0.05)
    with FmuInstance(fmus["SmaActuator"], "plant", {"load": 0.05}) as fmu:
        for k in range(100):
            fmu.set_real(("P_in", "load"), (0.8, 0.05))
            fmu.step(k * STEP, STEP)
            library.step(0.8, 0.05, STEP)
        fmu.set_real(("P_in", "load"), (power, load))
        with pytest.raises(FmuError, match="fmi2DoStep failed \\(discard\\)") as raised:
            fmu.step(100 * STEP, step)
        assert raised.value.status == DISCARD
        assert message in str(raised.value)
        assert "plant" in str(raised.value) and "t = 0.1" in str(raised.value)
        assert fmu.messages[-1][0] == "discard"
        # the rejected step changed nothing: the instance goes on like the library
        for k in range(100, 200):
            fmu.set_real(("P_in", "load"), (0.8, 0.05))
            fmu.step(k * STEP, STEP)
            out = library.step(0.8, 0.05, STEP)
        assert fmu.get_real(("R", "T")) == [out.R, out.T]


@pytest.mark.parametrize("reference,load,step,message", [
    (math.nan, 0.05, STEP, "R_ref must be finite, got nan"),
    (-41.0, 0.05, STEP, "R_ref must be > 0, got -41.0"),
    (41.0, -0.2, STEP, "load must be >= 0, got -0.2"),
    (41.0, math.inf, STEP, "load must be finite, got inf"),
])
def test_feedforward_discards_bad_input_and_stays_usable(fmus, params, reference, load, step, message):
    library = FeedforwardStepper(params)
    with FmuInstance(fmus["SmaFeedforward"], "ff", {"R_ref": 44.0, "load": 0.05}) as fmu:
        for k in range(50):
            fmu.set_real(("R_ref", "load"), (44.0 - 0.01 * k, 0.05))
            fmu.step(k * STEP, STEP)
            library.step(44.0 - 0.01 * k, 0.05, STEP)
        fmu.set_real(("R_ref", "load"), (reference, load))
        with pytest.raises(FmuError) as raised:
            fmu.step(50 * STEP, step)
        assert raised.value.status == DISCARD and message in str(raised.value)
        fmu.set_real(("R_ref", "load"), (43.0, 0.05))
        fmu.step(50 * STEP, STEP)
        out = library.step(43.0, 0.05, STEP)
        assert fmu.get_real(("P_ff", "T_ref")) == [out.P_ff, out.T_ref]


@pytest.mark.parametrize("name,start,message", [
    ("SmaActuator", {"hysteresis_mode": 3},
     "hysteresis_mode must be 1 (continuous) or 2 (switch), got 3"),
    ("SmaActuator", {"T_start": math.nan}, "T_start must be finite, got nan"),
    ("SmaActuator", {"R_P": -33.0}, "parameter phases.R_P = -33.0 must be in (0, 100000] [ohm]"),
    ("SmaActuator", {"memory_depth": 1},  # an Integer, printed as one (not 1.0)
     "parameter hysteresis.memory_depth = 1 must be a whole number in [2, 100000] [1]"),
    ("SmaActuator", {"load": -1.0}, "load must be >= 0, got -1.0"),
    ("SmaFeedforward", {"beta": 0.0}, "parameter control.beta = 0.0 must be in (0, 100000] [s]"),
    ("SmaFeedforward", {"R_ref": math.nan}, "R_ref must be finite, got nan"),
])
def test_bad_parameters_fail_initialization_with_a_message(fmus, name, start, message):
    with pytest.raises(FmuError, match="initialization failed") as raised:
        FmuInstance(fmus[name], "bad", start)
    assert message in str(raised.value)


@pytest.mark.parametrize("time,step,message", [
    (0.1, 0.0, "communicationStepSize = 0.0 s must be finite"),
    (0.1, -STEP, "communicationStepSize = -0.001 s must be finite"),
    (0.1, math.nan, "communicationStepSize = nan s must be finite"),
    (math.inf, STEP, "currentCommunicationPoint = inf s"),
    (0.05, STEP, "currentCommunicationPoint = 0.05 s, but the last step ended at 0.1"),
    (0.2, STEP, "currentCommunicationPoint = 0.2 s, but the last step ended at 0.1"),
])
def test_bad_communication_points_are_errors_and_change_nothing(fmus, params, time, step, message):
    library = PlantStepper(params, load=0.05)
    with FmuInstance(fmus["SmaActuator"], "clock", {"load": 0.05}) as fmu:
        for k in range(100):
            fmu.set_real(("P_in", "load"), (0.8, 0.05))
            fmu.step(k * STEP, STEP)
            library.step(0.8, 0.05, STEP)
        with pytest.raises(FmuError) as raised:
            fmu.step(time, step)
        assert raised.value.status == ERROR and message in str(raised.value)
        assert "fmi2DoStep" in str(raised.value)
        fmu.step(100 * STEP, STEP)
        out = library.step(0.8, 0.05, STEP)
        assert fmu.get_real(("R", "T")) == [out.R, out.T]


def test_bad_parameter_seen_by_a_plain_fmpy_host(fmus, tmp_path):
    """Straight fmpy: exitInitializationMode gives fmi2Error, the instance stays in
    Initialization Mode, and after a correction it initializes and steps."""
    from fmpy import extract, read_model_description
    from fmpy.fmi1 import FMICallException
    from fmpy.fmi2 import FMU2Slave

    description = read_model_description(str(fmus["SmaActuator"]))
    refs = {v.name: v.valueReference for v in description.modelVariables}
    fmu = FMU2Slave(guid=description.guid, unzipDirectory=extract(str(fmus["SmaActuator"]), tmp_path),
                    modelIdentifier="SmaActuator", instanceName="raw")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setReal([refs["h_c"]], [-106.0])
    with pytest.raises(FMICallException) as raised:
        fmu.getReal([refs["R"]])                       # outputs undefined with this h_c
    assert raised.value.status == ERROR
    with pytest.raises(FMICallException) as raised:
        fmu.exitInitializationMode()
    assert raised.value.status == ERROR
    fmu.setReal([refs["h_c"]], [106.0])                # still in Initialization Mode
    fmu.exitInitializationMode()
    fmu.doStep(0.0, STEP)
    assert all(math.isfinite(v) for v in fmu.getReal([refs["R"], refs["T"]]))
    fmu.terminate()
    fmu.freeInstance()


def test_log_messages_stay_with_their_instance(fmus):
    """Each instance keeps its own FMU log (no shared logger between instances)."""
    first = FmuInstance(fmus["SmaActuator"], "first", {"load": 0.05})
    second = FmuInstance(fmus["SmaActuator"], "second", {"load": 0.05})
    try:
        first.set_real(("P_in", "load"), (float("nan"), 0.05))
        with pytest.raises(FmuError, match="SmaActuator 'first': step at t = 0.0 s discarded"):
            first.step(0.0, STEP)
        assert any("'first'" in text for _, text in first.messages)
        assert not any("'first'" in text for _, text in second.messages)
    finally:
        second.close()
        first.close()


def test_leaving_the_validity_range_warns_once_per_excursion(fmus, params):
    """100 W for 1 s (far above T_max), 3 s off (back below), 1 s on: two warnings."""
    with FmuInstance(fmus["SmaActuator"], "hot", {"load": 0.05}) as fmu:
        temperatures, warned_at = [], []
        for k in range(5000):
            fmu.set_real(("P_in", "load"), (0.0 if 1000 <= k < 4000 else 100.0, 0.05))
            seen = len(fmu.messages)
            fmu.step(k * STEP, STEP)                      # fmi2Warning does not raise
            temperatures.append(fmu.get_real(("T",))[0])
            warned_at += [k for status, _ in fmu.messages[seen:] if status == "warning"]
        warnings = [text for status, text in fmu.messages if status == "warning"]
    assert max(temperatures) > params.T_max > temperatures[3999]
    assert len(warnings) == 2 and f"validity.T_max = {params.T_max:g} degC" in warnings[0]
    assert temperatures[warned_at[0] - 1] <= params.T_max < temperatures[warned_at[0]]
    assert warned_at[1] > 4000


def test_tiny_and_huge_steps_keep_the_outputs_finite(fmus):
    with FmuInstance(fmus["SmaFeedforward"], "tiny", {"R_ref": 42.0, "load": 0.05}) as fmu:
        time = 0.0
        for step in (1e-3, 1e-310, 5e-324, 1e-3, 1e300):
            fmu.set_real(("R_ref", "load"), (41.0, 0.05))
            fmu.step(time, step)
            time += step
            assert all(math.isfinite(v) for v in fmu.get_real(("P_ff", "T_ref")))
