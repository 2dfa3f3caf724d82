"""A saved state whose contents were edited and whose checksum was recomputed is refused by
name in both families and both FMI versions, before any output is served.

The fuzz campaign's finding: the C family took such a state of SmaActuator and then served
R = -1e300 ohm, T = -500 degC or xi_M = 2.0 as fmi2OK until the next step (the pythonfmu
family recomputed the outputs from the hidden state it checked). Now each family checks the
hidden model state's entries (finite, in their physical ranges: runtime/state_entries.py and
c_family/runtime/state_entries.c) and that the outputs the stepper holds are the ones it
gives (StepperSlave._set_fmu_state, c_family/core/layer_states.c). The refusal is fmi2Error
/ fmi3Error at SetFMUstate, naming the entry, its unit and the range or the value; the
instance is unchanged and steps on; the same bytes with nothing edited restore."""
import json
import struct
import zlib

import pytest
from fmpy import read_model_description

from fmi3_twins import Instance3
from native_twins import Instance

pytestmark = pytest.mark.needs("gcc")

MODEL = "SmaActuator"
HEADER = 20   # the frame: SMAF, version, body length, CRC-32 (docs/fmus.md, "State")

# (what is edited, its new value, words the refusal logs)
OUTPUTS = [("R", -1e300, ["output R = ", " ohm is not what the saved model state gives"]),
           ("T", -500.0, ["output T = -500", " degC is not what the saved model state gives"]),
           ("xi_M", 2.0, ["output xi_M = 2", "is not what the saved model state gives"])]
ENTRIES = [("temperature", 0, -500.0,
            ["state entry temperature = -500", "must be finite and in [-273.15, 300] degC"]),
           ("temperature", 0, 1e300, ["state entry temperature = 1", "[-273.15, 300] degC"]),
           ("xi_MF", 3, 2.0, ["state entry xi_MF = 2", "must be finite and in [0, 1]"]),
           ("load", 2, -1.0, ["state entry load = -1", "must be finite and in [0, inf] kg"])]


def _framed(body):
    return (b"SMAF" + (1).to_bytes(4, "little") + len(body).to_bytes(8, "little")
            + zlib.crc32(body).to_bytes(4, "little") + body)


def _text(body, at):
    size = struct.unpack_from("<I", body, at)[0]
    return at + 4 + size


def c_offsets(blob, variables):
    """{variable name or stepper entry index: byte offset of its value in ``blob``}, a C-family
    state (c_family/core/layer_state_bytes.c: header, model, wire digest, GUID, format,
    calling state, four times, three flags, initial_error, the variables, the stepper's
    doubles)."""
    body, at, where = blob[HEADER:], 16, {}
    for _ in range(4):
        at = _text(body, at)
    at = _text(body, at + 4 + 4 * 8 + 3)
    assert struct.unpack_from("<I", body, at)[0] == len(variables)
    at += 4
    for variable in variables:
        where[variable.name] = HEADER + at
        at = _text(body, at) if variable.type == "String" else at + (
            8 if variable.type == "Real" else 4)
    count = struct.unpack_from("<I", body, at + 1)[0]
    at += 5
    where.update({index: HEADER + at + 8 * index for index in range(count)})
    assert at + 8 * count == len(body)
    return where


def c_edited(blob, variables, key, value):
    """``blob`` with the double at ``key`` set to ``value`` and the checksum recomputed."""
    edited = bytearray(blob)
    struct.pack_into("<d", edited, c_offsets(blob, variables)[key], value)
    return _framed(bytes(edited[HEADER:]))


def python_edited(blob, key, value, stepper):
    """A pythonfmu-family state with a variable (or ``stepper`` entry) set to ``value``."""
    document = json.loads(blob[HEADER:])
    (document["__stepper__"] if stepper else document)[key] = value
    return _framed(json.dumps(document).encode())


class Side:
    """One FMU of one family and FMI version, driven away from its start."""

    def __init__(self, kind, path, variables, name, inputs=(("P_in", 1.0),)):
        self.kind, self.variables = kind, variables
        self.fmu = (Instance3 if kind == "c-fmi3" else Instance)(path, name)
        assert self.fmu.start() == 0
        for input_name, value in inputs:
            assert self.fmu.set(input_name, value) == 0
        for k in range(20):
            assert self.fmu.step(k * 1e-3, 1e-3) == 0
        self.time = 20e-3
        self.blob = self.serialized()

    def serialized(self):
        fmu = self.fmu.fmu
        if self.kind == "c-fmi3":
            return bytes(fmu.serializeFMUState(fmu.getFMUState()))
        return bytes(fmu.serializeFMUstate(fmu.getFMUstate()))

    def restore(self, blob):
        """(status of DeSerialize, status of SetFMUstate or None)."""
        names = (("deserializeFMUState", "setFMUState") if self.kind == "c-fmi3"
                 else ("deSerializeFMUstate", "setFMUstate"))
        status, state = self.fmu.call(names[0], blob)
        return status, (None if status else self.fmu.call(names[1], state)[0])

    def edited(self, key, value, stepper=False):
        if self.kind == "python":
            names = {"temperature": "temperature", "xi_MF": "xi_MF", "load": "load"}
            return python_edited(self.blob, names.get(key, key), value, stepper)
        return c_edited(self.blob, self.variables, key, value)


@pytest.fixture(params=["python", "c-fmi2", "c-fmi3"])
def side(request, fmus, native_fmus, fmi3_fmus):
    paths = {"python": fmus, "c-fmi2": native_fmus, "c-fmi3": fmi3_fmus}[request.param]
    variables = read_model_description(str(native_fmus[MODEL])).modelVariables
    made = Side(request.param, paths[MODEL], variables, f"crafted-{request.param}-{id(request)}")
    yield made
    made.fmu.close()


def _refused(side, blob, words):
    before = side.fmu.values()
    assert side.restore(blob) == (0, 3)      # the frame is intact: refused at SetFMUstate
    message = side.fmu.log[-1][1]
    assert "state refused, the instance is unchanged" in message, message
    for word in words:
        assert word in message, (word, message)
    assert side.fmu.values() == before
    assert side.fmu.step(side.time, 1e-3) == 0                   # and it goes on
    side.time += 1e-3


@pytest.mark.parametrize("name,value,words", OUTPUTS)
def test_an_edited_output_is_refused_naming_it_its_unit_and_the_value(side, name, value, words):
    _refused(side, side.edited(name, value), words)


@pytest.mark.parametrize("key,index,value,words", ENTRIES)
def test_an_edited_hidden_entry_is_refused_naming_it_and_its_range(side, key, index, value, words):
    blob = side.edited(key if side.kind == "python" else index, value, stepper=True)
    _refused(side, blob, words)


def test_the_same_bytes_with_a_recomputed_checksum_restore(side):
    """Nothing edited: the check refuses edits, not re-framed states (the outputs a restored
    stepper gives are the saved ones, bit for bit)."""
    after = side.fmu.values()
    blob = side.edited("R", after["R"]) if side.kind != "python" else python_edited(
        side.blob, "R", after["R"], False)
    assert blob == side.blob or side.kind == "python"
    assert side.restore(blob) == (0, 0)
    assert side.fmu.values() == after


# the compensator's search tangent (previous_exponent [1], previous_slope [K]; C layout:
# stepper doubles 6 and 7, feedforward.h): a bad slope, and a tangent without its slope
TANGENT_EDITS = [("previous_slope", 7, -1.0,
                  ["state entry previous_slope = -1", "must be finite and in [", "] K"]),
                 ("previous_slope", 7, 0.0, ["state entry previous_slope = 0"]),
                 ("previous_exponent", 6, 0.5,
                  ["state entries previous_exponent and previous_slope must both be numbers or "
                   "both be null"])]


@pytest.fixture(params=["python", "c-fmi2", "c-fmi3"])
def compensator_side(request, fmus, native_fmus, fmi3_fmus):
    paths = {"python": fmus, "c-fmi2": native_fmus, "c-fmi3": fmi3_fmus}[request.param]
    variables = read_model_description(str(native_fmus["SmaFeedforward"])).modelVariables
    made = Side(request.param, paths["SmaFeedforward"], variables,
                f"crafted-ff-{request.param}-{id(request)}", (("R_ref", 42.0), ("load", 0.25)))
    yield made
    made.fmu.close()


@pytest.mark.parametrize("key,index,value,words", TANGENT_EDITS)
def test_an_edited_search_tangent_is_refused_naming_it(compensator_side, key, index, value,
                                                       words):
    """The compensator's new entries are checked like the others, in both families and both
    FMI versions (on the reference wire the tangent is null: one stage, no search)."""
    side = compensator_side
    blob = side.edited(key if side.kind == "python" else index, value, stepper=True)
    _refused(side, blob, words)
