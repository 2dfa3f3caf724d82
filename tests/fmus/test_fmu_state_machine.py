"""The FMI 2.0 co-simulation calling sequence, driven with plain fmpy (``FMU2Slave``).

Each illegal call gives fmi2Error with a message naming the function (and the variable and
value) and changes nothing; outputs in Initialization Mode follow what was set there;
states of another build or corrupt states are refused and leave the instance as it was.
"""
import json
import math
import zlib

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE

from sma_fmu.fmi.packaging.build import build_fmu
from sma_fmu.wire.parameter_file import write_parameter_file
from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.plant import PlantStepper

ERROR = 3


class Raw:
    """One FMU instance through fmpy's FMU2Slave, with its log messages and refs by name."""

    def __init__(self, path, folder, name="raw"):
        description = read_model_description(str(path))
        self.refs = {v.name: v.valueReference for v in description.modelVariables}
        self.messages = []
        self.fmu = FMU2Slave(guid=description.guid, unzipDirectory=extract(str(path), folder),
                             modelIdentifier=description.coSimulation.modelIdentifier, instanceName=name)
        callbacks = fmi2CallbackFunctions()
        self._logger = callbacks.logger = fmi2CallbackLoggerTYPE(
            lambda env, name, status, category, message: self.messages.append(
                (status, message.decode().replace("%%", "%"))))
        self.fmu.instantiate(callbacks=callbacks)

    def start(self, **values):
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        self.set(**values)
        self.fmu.exitInitializationMode()

    def set(self, **values):
        for name, value in values.items():
            setter = self.fmu.setInteger if isinstance(value, int) else self.fmu.setReal
            setter([self.refs[name]], [value])

    def get(self, *names):
        return self.fmu.getReal([self.refs[name] for name in names])

    def refused(self, call, *args, words=()):
        """Assert ``call(*args)`` gives fmi2Error with a message holding ``words``."""
        seen = len(self.messages)
        with pytest.raises(FMICallException) as raised:
            call(*args)
        assert raised.value.status == ERROR
        text = " ".join(message for status, message in self.messages[seen:] if status == ERROR)
        for word in words:
            assert word in text, (word, text)

    def close(self):
        self.fmu.freeInstance()


@pytest.fixture
def plant(fmus, tmp_path):
    raw = Raw(fmus["SmaActuator"], tmp_path / "plant")
    yield raw
    raw.close()


def test_calls_out_of_sequence_are_errors(plant):
    fmu = plant.fmu
    plant.refused(fmu.exitInitializationMode, words=["fmi2ExitInitializationMode", "instantiated"])
    plant.refused(fmu.doStep, 0.0, 1e-3, words=["fmi2DoStep"])
    plant.refused(fmu.getReal, [plant.refs["R"]], words=["fmi2GetReal"])
    plant.start(load=0.05)
    plant.refused(fmu.enterInitializationMode, words=["fmi2EnterInitializationMode", "stepComplete"])
    plant.refused(fmu.setupExperiment, None, 0.0, words=["fmi2SetupExperiment"])
    fmu.doStep(0.0, 1e-3)
    fmu.terminate()
    plant.refused(fmu.doStep, 1e-3, 1e-3, words=["fmi2DoStep", "terminated"])
    plant.refused(fmu.terminate, words=["fmi2Terminate"])
    assert math.isfinite(plant.get("R")[0])  # reading the final values is allowed
    fmu.reset()                               # back to instantiated: a new run
    plant.start(load=0.05)
    fmu.doStep(0.0, 1e-3)


def test_only_inputs_and_parameters_can_be_set_and_fixed_ones_only_before_initialization(plant, params):
    plant.start(load=0.05)
    plant.fmu.doStep(0.0, 1e-3)
    R, T = plant.get("R", "T")
    plant.refused(lambda: plant.set(R=1.0), words=["fmi2SetReal", "R (value reference", "output", "1.0"])
    plant.refused(lambda: plant.set(R_P=30.0), words=["R_P", "fixed parameter", "30.0"])
    plant.refused(lambda: plant.set(hysteresis_mode=2), words=["fmi2SetInteger", "hysteresis_mode"])
    plant.refused(plant.fmu.setReal, [plant.refs["P_in"], plant.refs["R"]], [1.0, 2.0],
                  words=["nothing was set"])
    assert plant.get("R", "T", "R_P", "P_in") == [R, T, params.R_P, 0.0]  # nothing changed
    plant.refused(plant.fmu.getReal, [123456], words=["value reference 123456"])
    plant.refused(plant.fmu.getReal, list(range(123456, 123556)),
                  words=["value reference 123460", ", and 95 more"])
    assert "value reference 123461" not in plant.messages[-1][1]
    plant.refused(plant.fmu.getBoolean, [plant.refs["R"]], words=["Real variable R, not a Boolean"])
    plant.set(P_in=0.5)                       # inputs can be set
    plant.fmu.doStep(1e-3, 1e-3)


def test_a_refused_long_string_is_shown_cut_not_whole(plant):
    """A host's 5-kB string is named in the refusal by its first 200 characters and its
    length, as the C family shows it, not echoed whole into the host's log."""
    text = "%s%n%x" * 1000
    plant.refused(plant.fmu.setString, [plant.refs["wire_digest"]], [text],
                  words=["wire_digest", "nothing was set", "(6000 characters)"])
    message = plant.messages[-1][1]
    assert len(message) < 600 and text[:200] in message and text[:201] not in message


def test_reinitialization_is_refused_and_keeps_the_wire_state(plant):
    plant.start(load=0.05, P_in=3.0)
    for k in range(500):
        plant.fmu.doStep(k * 1e-3, 1e-3)
    hot = plant.get("T")
    plant.refused(plant.fmu.enterInitializationMode)
    assert plant.get("T") == hot and hot[0] > 20.0


def test_outputs_in_initialization_mode_follow_what_is_set(fmus, tmp_path, params):
    raw = Raw(fmus["SmaFeedforward"], tmp_path / "ff")
    raw.fmu.setupExperiment(startTime=0.0)
    raw.fmu.enterInitializationMode()
    for reference, load in ((44.0, 0.05), (41.0, 0.2)):
        raw.set(R_ref=reference, load=load)
        expected = FeedforwardStepper(params).initial_outputs(reference, load)
        assert raw.get("P_ff", "T_ref") == [expected.P_ff, expected.T_ref]
    raw.set(beta=0.0)                           # invalid until corrected
    raw.refused(raw.fmu.getReal, [raw.refs["P_ff"]], words=["control.beta = 0.0"])
    raw.set(beta=0.2)
    raw.fmu.exitInitializationMode()
    raw.close()
    plant = Raw(fmus["SmaActuator"], tmp_path / "plant")
    plant.fmu.setupExperiment(startTime=0.0)
    plant.fmu.enterInitializationMode()
    plant.set(T_start=80.0, load=0.1)
    expected = PlantStepper(params, T_start=80.0, load=0.1).outputs
    assert plant.get("R", "T") == [expected.R, expected.T]
    plant.close()


def _header(payload):
    """The front's header for serialized state bytes: magic, version, length, CRC-32."""
    return (b"SMAF" + (1).to_bytes(4, "little") + len(payload).to_bytes(8, "little")
            + zlib.crc32(payload).to_bytes(4, "little"))


def test_states_of_another_build_or_corrupt_ones_are_refused(fmus, tmp_path, parameter_set):
    changed = parameter_set.params.replace(R_P=30.0)
    model = write_parameter_file(tmp_path / "wire.toml", changed, "r30", "", parameter_set.meanings)
    other = Raw(build_fmu("SmaActuator", tmp_path / "other", model), tmp_path / "o")
    other.start(load=0.05, P_in=2.0)
    other.fmu.doStep(0.0, 0.5)
    foreign = other.fmu.serializeFMUstate(other.fmu.getFMUstate())
    other.close()

    plant = Raw(fmus["SmaActuator"], tmp_path / "p")
    plant.start(load=0.05, P_in=1.0)
    plant.fmu.doStep(0.0, 0.5)
    own = bytes(plant.fmu.serializeFMUstate(plant.fmu.getFMUstate()))
    before = plant.get("R", "T", "R_P")
    state = plant.fmu.deSerializeFMUstate(foreign)  # a well-formed state ...
    plant.refused(plant.fmu.setFMUstate, state, words=["another wire"])  # ... of another wire
    document = json.loads(own[20:])
    for corrupt in ({**document, "__stepper__": {**document["__stepper__"], "temperature": "hot"}},
                    {k: v for k, v in document.items() if k != "T_start"},
                    {**document, "R": True},
                    {**document, "extra": 1.0},
                    {**document, "__stepper__": None},  # forged: initialized without a stepper
                    {**document, "__stepper__": None, "__fmi__": {**document["__fmi__"], "state": "terminated"}}):
        payload = json.dumps(corrupt).encode()
        state = plant.fmu.deSerializeFMUstate(_header(payload) + payload)
        plant.refused(plant.fmu.setFMUstate, state, words=["state refused, the instance is unchanged"])
    assert plant.get("R", "T", "R_P") == before
    plant.fmu.doStep(0.5, 0.5)                      # and it goes on
    plant.close()
