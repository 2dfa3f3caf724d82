"""The cases the last fuzz campaign found, pinned through the plain C host so they stay fixed:
absurd loads are refused or warned about (naming the load), edited saved states are refused
(naming the entry) and leave the instance as it was."""
import json
import zlib

import pytest
from fmpy import read_model_description

from fmi_host import DISCARD, ERROR, FATAL, OK, WARNING, FmiHost


def _refs(folder):
    return {v.name: v.valueReference for v in
            read_model_description(str(folder / "modelDescription.xml")).modelVariables}


def _framed(document):
    payload = json.dumps(document).encode()
    return (b"SMAF" + (1).to_bytes(4, "little") + len(payload).to_bytes(8, "little")
            + zlib.crc32(payload).to_bytes(4, "little") + payload)


@pytest.fixture()
def started(unpacked, fmi_host_exe):
    """start(name) -> (host, refs): an instance of FMU ``name`` after initialization."""
    hosts = []

    def start(name):
        folder = unpacked[name]
        host = FmiHost(fmi_host_exe, folder)
        hosts.append(host)
        assert host.call("instantiate 0 706c616e74 ok ok 1").status == OK
        for command in ("setup 0 0.0 -", "enter 0", "exit 0"):
            assert host.call(command).status == OK
        return host, _refs(folder)
    yield start
    for host in hosts:
        if host.alive:
            host.call("free 0")
            assert host.close() == 0


@pytest.mark.parametrize("name,load_input", [("SmaActuator", "load"), ("SmaFeedforward", "load")])
def test_a_load_beyond_the_validity_limit_warns_once_naming_it(started, name, load_input):
    host, refs = started(name)
    assert host.call(f"setreal 0 1 {refs[load_input]} 100.0").status == OK
    first = host.call("step 0 0.0 0.001")
    second = host.call("step 0 0.001 0.001")
    assert first.status == WARNING and second.status == OK
    assert any("load = 100 kg rose above the validity limit" in m for m in first.logged(WARNING))
    assert not second.logged(WARNING)


@pytest.mark.parametrize("name", ["SmaActuator", "SmaFeedforward"])
def test_a_load_that_overflows_the_model_discards_the_step_naming_the_load(started, name):
    host, refs = started(name)
    assert host.call(f"setreal 0 1 {refs['load']} 1e308").status == OK
    reply = host.call("step 0 0.0 0.001")
    assert reply.status == DISCARD
    assert any("load = 1e+308 kg is beyond the model's range" in m for m in reply.logged(DISCARD))


@pytest.mark.parametrize("name,entry,value,words", [
    ("SmaActuator", "xi_P", -5.0, "xi_P"),
    ("SmaActuator", "xi_MF", -5.0, "xi_MF"),
    ("SmaActuator", "temperature", 1e308, "temperature"),
    ("SmaFeedforward", "previous_reference", "hot", "previous_reference must be a number"),
    ("SmaFeedforward", "previous_slope", -1.0, "state entry previous_slope = -1.0 must be"),
    ("SmaFeedforward", "previous_exponent", 0.5, "previous_exponent and previous_slope must"),
])
def test_an_edited_saved_state_is_refused_naming_the_entry(started, name, entry, value, words):
    host, refs = started(name)
    host.call("step 0 0.0 0.001")
    assert host.call("getstate 0 0").status == OK
    saved = host.call("serialize 0 0")
    document = json.loads(bytes.fromhex(saved.values[0])[20:])
    before = host.call(f"getreal 0 1 {refs['T' if name == 'SmaActuator' else 'T_ref']}").values
    document["__stepper__"][entry] = value
    assert host.call(f"deserialize 0 1 {_framed(document).hex()}").status == OK
    reply = host.call("setstate 0 1")
    assert reply.status == ERROR and reply.status != FATAL
    assert any(words in m for m in reply.logged(ERROR))
    after = host.call(f"getreal 0 1 {refs['T' if name == 'SmaActuator' else 'T_ref']}").values
    assert after == before
    assert host.call("step 0 0.001 0.001").status == OK          # and it goes on
