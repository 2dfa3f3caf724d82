"""The loop's block FMUs for system tools: SmaPiController and SmaScenarioSignals.

Both are driven through fmpy and compared with the runtime code the library loop uses
(exactly: the FMUs run the same Python); Initialization Mode is checked with fmpy's raw
FMU2Slave, where outputs are read before exitInitializationMode as libcosim and Ecos do.
"""
import json
import math

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from fmu_signals import STEP, reference
from sma_fmu.fmi.packaging.fmu_names import FMU_SCRIPTS
from sma_fmu.fmi.packaging.build import validate_fmus
from sma_fmu.fmi.driving.instance import FmuError, FmuInstance
from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.pi_control import PIController
from sma_fmu.runtime.scenario_signals import SignalSource, signals_from_text, table_text
from sma_fmu.runtime.signals import load_from_table, reference_from_table

TABLES = {
    "constant": {"kind": "constant", "value_ohm": 40.0},
    "step": {"kind": "step", "initial_ohm": 46.0, "final_ohm": 40.0, "time_s": 0.05},
    "ramp": {"kind": "ramp", "start_ohm": 46.0, "end_ohm": 38.0, "start_time_s": 0.02,
             "end_time_s": 0.08},
    "sine": {"kind": "sine", "offset_ohm": 41.0, "amplitude_ohm": 5.0, "frequency_hz": 3.0,
             "phase_deg": 30.0},
    "cosine": {"kind": "cosine", "offset_ohm": 41.85, "amplitude_ohm": 6.05, "frequency_hz": 0.5},
    "table": {"kind": "table", "times_s": [0.0, 0.03, 0.09], "values_ohm": [45.0, 39.0, 42.0]},
}
LOAD = {"times_s": [0.0, 0.04, 0.07], "values_kg": [0.0032, 0.05, 0.15]}


def _units(path):
    return {v.name: v.unit for v in read_model_description(str(path)).modelVariables
            if v.type == "Real"}


@pytest.mark.parametrize("name", ["SmaPiController", "SmaScenarioSignals"])
def test_new_fmus_are_built_valid_and_declare_every_unit(fmus, name):
    assert name in FMU_SCRIPTS
    assert validate_fmus([fmus[name]]) == {fmus[name]: []}
    units = _units(fmus[name])
    assert units and all(units.values()), units


def _pi_inputs(k):
    """R, R_ref, P_ff [ohm, ohm, W]: crosses the clamp (negative sum) and back."""
    t = k * STEP
    return 44.0 + 4.0 * math.sin(2 * math.pi * 2.0 * t), reference(k), 1.5 * math.cos(2 * math.pi * t)


def test_pi_controller_fmu_is_the_runtime_pi(fmus):
    library = PIController(0.4, 2.5)
    clamped = 0
    with FmuInstance(fmus["SmaPiController"], "pi", {"Kp": 0.4, "Ki": 2.5}) as fmu:
        for k in range(1500):
            inputs = _pi_inputs(k)
            fmu.set_real(("R", "R_ref", "P_ff"), inputs)
            fmu.step(k * STEP, STEP)
            expected = library.sample(*inputs, STEP)
            assert tuple(fmu.get_real(("P", "P_fb"))) == expected
            clamped += expected[0] == 0.0
    assert 0 < clamped < 1500  # the run went through the clamp and the anti-windup


def _raw_instance(path, name, tmp_path):
    description = read_model_description(str(path))
    fmu = FMU2Slave(guid=description.guid, unzipDirectory=extract(str(path), str(tmp_path / name)),
                    modelIdentifier=description.coSimulation.modelIdentifier, instanceName=name)
    fmu.instantiate()
    refs = {v.name: v.valueReference for v in description.modelVariables}
    return fmu, refs


def test_outputs_follow_inputs_in_initialization_mode(fmus, params, tmp_path):
    """libcosim and Ecos read outputs in Initialization Mode to pass start values on."""
    fmu, refs = _raw_instance(fmus["SmaPiController"], "pi", tmp_path)
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    for inputs in ((45.0, 42.0, 0.7), (40.0, 42.0, 0.2)):  # the second one clamps at 0 W
        fmu.setReal([refs["R"], refs["R_ref"], refs["P_ff"]], list(inputs))
        expected = PIController(params.Kp, params.Ki).preview(*inputs)
        assert tuple(fmu.getReal([refs["P"], refs["P_fb"]])) == expected
    fmu.exitInitializationMode()
    fmu.doStep(0.0, STEP)  # the first step gives what was shown before it
    assert tuple(fmu.getReal([refs["P"], refs["P_fb"]])) == expected
    fmu.terminate()
    fmu.freeInstance()

    fmu, refs = _raw_instance(fmus["SmaFeedforward"], "ff", tmp_path)
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setReal([refs["R_ref"], refs["load"]], [44.0, 0.15])
    expected = FeedforwardStepper(params).initial_outputs(44.0, 0.15)
    assert fmu.getReal([refs["P_ff"], refs["T_ref"]]) == [expected.P_ff, expected.T_ref]
    fmu.exitInitializationMode()
    fmu.terminate()
    fmu.freeInstance()


def test_pi_controller_discards_non_finite_inputs_and_rejects_bad_gains(fmus):
    with FmuInstance(fmus["SmaPiController"], "pi") as fmu:
        fmu.set_real(("R", "R_ref", "P_ff"), (44.0, math.nan, 0.0))
        with pytest.raises(FmuError, match="R_ref must be finite, got nan"):
            fmu.step(0.0, STEP)
        fmu.set_real(("R_ref",), (42.0,))
        fmu.step(0.0, STEP)  # the rejected step changed nothing: retry from the same time
        assert fmu.get_real(("P",))[0] == pytest.approx(0.3 * 2.0)
    with pytest.raises(FmuError, match=r"control.Kp = -1.0 must be in \[0, 1e\+06\] \[W/ohm\]"):
        FmuInstance(fmus["SmaPiController"], "pi", {"Kp": -1.0})


@pytest.mark.parametrize("kind", sorted(TABLES))
def test_signals_fmu_outputs_the_scenario_signals_at_each_communication_point(fmus, kind):
    signal, load = reference_from_table(TABLES[kind]), load_from_table(LOAD)
    start = {"reference": table_text(TABLES[kind]), "load_profile": table_text(LOAD)}
    with FmuInstance(fmus["SmaScenarioSignals"], kind, start, start_time=0.01) as fmu:
        assert fmu.get_real(("R_ref", "load")) == [signal.value(0.01), load.value(0.01)]
        for k in range(100):
            t = 0.01 + k * STEP
            fmu.step(t, STEP)
            end = 0.01 + (k + 1) * STEP  # on the grid start + k h (t + STEP may round off it)
            assert fmu.get_real(("R_ref", "load")) == [signal.value(end), load.value(end)]


def test_signals_fmu_defaults_are_the_paper_load_step_signals(fmus):
    from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios

    scenario = load_scenario(resolve_scenarios(["load-step-pi+ff-adaptive"])[0])
    variables = {v.name: v for v in read_model_description(str(fmus["SmaScenarioSignals"])).modelVariables}
    assert json.loads(variables["reference"].start) == scenario.reference.as_table()
    assert json.loads(variables["load_profile"].start) == scenario.load.as_table()


@pytest.mark.parametrize("start, message", [
    ({"reference": '{"kind":"cosin"}'}, "reference: kind must be one of constant"),
    ({"reference": "{not json"}, "reference is not valid JSON"),
    ({"reference": "[40.0]"}, "reference must be a JSON object"),
    ({"load_profile": '{"times_s":[0.0],"values_kg":[-0.1]}'}, "load_profile: values_kg must be >= 0"),
    ({"load_profile": '{"times_s":[1.0],"values_kg":[0.1]}'}, "load_profile: times_s must start at 0"),
])
def test_signals_fmu_reports_bad_tables_naming_the_parameter(fmus, start, message):
    with pytest.raises(FmuError, match=message):
        FmuInstance(fmus["SmaScenarioSignals"], "signals", start)


def test_signal_text_round_trips_and_rejects_non_finite_numbers():
    for table in TABLES.values():
        signal, _ = signals_from_text(table_text(table), table_text(LOAD))
        assert signal.as_table() == reference_from_table(table).as_table()
    assert " " not in table_text(TABLES["table"])  # containers split start values at spaces
    with pytest.raises(ValueError, match="reference: offset_ohm must be a finite number"):
        signals_from_text('{"kind":"cosine","offset_ohm":NaN,"amplitude_ohm":1,"frequency_hz":1}',
                          table_text(LOAD))
    source = SignalSource(reference_from_table(TABLES["step"]), load_from_table(LOAD))
    with pytest.raises(ValueError, match="step_size must be > 0"):
        source.step(0.0, 0.0)


@pytest.mark.parametrize("name, start, inputs", [
    ("SmaPiController", {}, ("R", "R_ref", "P_ff")),
    ("SmaScenarioSignals", {"reference": table_text(TABLES["sine"])}, ()),
])
def test_state_restore_reruns_identically(fmus, name, start, inputs):
    outputs = ("P", "P_fb") if inputs else ("R_ref", "load")

    def run(fmu, first, last):
        trace = []
        for k in range(first, last):
            if inputs:
                fmu.set_real(inputs, _pi_inputs(k))
            fmu.step(k * STEP, STEP)
            trace.append(tuple(fmu.get_real(outputs)))
        return trace

    with FmuInstance(fmus[name], name, start) as fmu:
        run(fmu, 0, 300)
        state = fmu.deserialize_state(fmu.serialize_state(fmu.get_state()))
        first = run(fmu, 300, 600)
        fmu.set_state(state)
        assert run(fmu, 300, 600) == first
        assert len(set(first)) > 1  # the outputs moved, so the state mattered
        fmu.free_state(state)
