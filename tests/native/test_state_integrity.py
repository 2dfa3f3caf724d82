"""Serialized states of both families are framed and checksummed alike (issue 38, F1):
"SMAF" | u32 version | u64 body length | u32 CRC-32 of the body | body. Every byte of a
saved state flipped (one bit, all bits), every truncation, a byte appended and a length field
that overflows: each case is refused at fmi2DeSerializeFMUstate naming what failed, or (never
seen, but allowed by the contract) restores a state identical to the saved one."""
import struct
import zlib

import pytest

from native_twins import Instance

pytestmark = pytest.mark.needs("gcc")

# model: (input, values it takes in turn) driving it away from its start before the save
DRIVE = {"SmaActuator": ("P_in", (0.5, 2.0, 0.0)), "SmaFeedforward": ("R_ref", (45.0, 40.0, 43.0)),
         "SmaPiController": ("R", (40.0, 35.0, 38.0)), "SmaPwmDriver": ("P_demand", (3.0, 7.5, 1.0)),
         "SmaScenarioSignals": (None, ())}


def _saved(fmu, model):
    """The serialized state of ``fmu`` after 30 driven steps."""
    name, values = DRIVE[model]
    assert fmu.start() == 0
    for k in range(30):
        if name:
            assert fmu.set(name, values[k // 10]) == 0
        assert fmu.step(k * 1e-3, 1e-3) <= 1
    return bytes(fmu.fmu.serializeFMUstate(fmu.fmu.getFMUstate()))


def _cases(blob):
    """(label, bytes) of every corruption of ``blob`` the sweep makes."""
    for at in range(len(blob)):
        for mask in (0x01, 0xFF):
            yield f"byte {at} ^ {mask:#x}", blob[:at] + bytes([blob[at] ^ mask]) + blob[at + 1:]
    for size in range(len(blob)):
        yield f"truncated to {size}", blob[:size]
    yield "a byte appended", blob + b"\0"
    for length in (2 ** 64 - 1, 2 ** 63, len(blob) - 20 + 2 ** 32):
        yield f"length field {length}", blob[:8] + struct.pack("<Q", length) + blob[16:]


def _sweep(fmu, blob):
    """{label: log line} of the refused cases; asserts an accepted one restores ``blob``."""
    refused = {}
    for label, bad in _cases(blob):
        status, state = fmu.call("deSerializeFMUstate", bad)
        if status == 0:  # allowed only if it is the very same state
            assert fmu.call("setFMUstate", state)[0] == 0, label
            assert bytes(fmu.fmu.serializeFMUstate(fmu.fmu.getFMUstate())) == blob, label
        else:
            assert status == 3, (label, status)
            refused[label] = fmu.log[-1][1]
    return refused


@pytest.fixture(scope="module", params=["python", "native"])
def family(request):
    """The FMUs of one family: {name: path}."""
    return request.getfixturevalue("fmus" if request.param == "python" else "native_fmus")


@pytest.mark.parametrize("model", sorted(DRIVE))
def test_every_corruption_of_a_saved_state_is_refused_naming_what_failed(family, model):
    fmu = Instance(family[model], f"sweep-{model}")
    try:
        blob = _saved(fmu, model)
        assert blob[:4] == b"SMAF" and struct.unpack_from("<IQI", blob, 4) == (
            1, len(blob) - 20, zlib.crc32(blob[20:]))
        before = fmu.values()
        refused = _sweep(fmu, blob)
        assert len(refused) == len(list(_cases(blob)))  # a CRC-32 leaves none through
        assert fmu.values() == before  # nothing refused changed the instance
        assert "checksum does not match" in refused["byte 20 ^ 0x1"]
        assert "checksum does not match" in refused[f"byte {len(blob) - 1} ^ 0xff"]
        assert "does not start with SMAF" in refused["byte 0 ^ 0x1"]
        assert "header version" in refused["byte 4 ^ 0x1"]
        assert "length field says" in refused[f"truncated to {len(blob) - 1}"]
        assert "shorter than the 20-byte header" in refused["truncated to 19"]
        assert "length field says 18446744073709551615" in refused[f"length field {2 ** 64 - 1}"]
        assert all("refused" in line or "not a state serialized" in line for line in refused.values())
        status, state = fmu.call("deSerializeFMUstate", blob)  # the intact bytes still restore
        assert status == 0 and fmu.call("setFMUstate", state)[0] == 0
        assert fmu.values() == before
    finally:
        fmu.close()


def test_a_state_of_the_other_family_is_refused_by_its_body(fmus, native_fmus):
    """Same frame, other body: the C family names its own body header, the pythonfmu one its
    JSON; neither takes the other's state."""
    python, native = Instance(fmus["SmaPwmDriver"], "twin-py"), Instance(native_fmus["SmaPwmDriver"],
                                                                         "twin-c")
    try:
        from_python, from_native = _saved(python, "SmaPwmDriver"), _saved(native, "SmaPwmDriver")
        assert native.call("deSerializeFMUstate", from_python)[0] == 3
        assert "no SMAFMU2S header" in native.log[-1][1]
        status, state = python.call("deSerializeFMUstate", from_native)
        assert status == 3 or python.call("setFMUstate", state)[0] == 3
    finally:
        python.close()
        native.close()
