"""Fuzzing the FMUs through a plain C host process (sma_fmu/fmi/hosts/fmi_host.c), with hypothesis.

Random instance names, resource URIs, call sequences, value references, values, strings
and state bytes go to every FMU of FMU_SCRIPTS. After every call: the host process is
alive, no call returned fmi2Fatal, a Real output read with fmi2OK/fmi2Warning is finite,
and every fmi2Discard or fmi2Error came with a logged message (logging is never switched
off here; with loggingOn false too). Each case ends with fmi2FreeInstance.

About 200 cases in CI (100 per FMU, derandomized so CI is repeatable); set
SMA_FMU_FUZZ_EXAMPLES=N for N random cases per FMU.
"""
import json
import math
import os
import zlib

import pytest
from fmpy import read_model_description
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fmi_host import DISCARD, FATAL, FmiHost, text
from sma_fmu.fmi.packaging.fmu_names import FMU_SCRIPTS

EXAMPLES = int(os.environ.get("SMA_FMU_FUZZ_EXAMPLES", "0"))
FUZZ = settings(max_examples=EXAMPLES or 100, derandomize=not EXAMPLES, deadline=None,
                database=None, suppress_health_check=list(HealthCheck))

SPECIAL_FLOATS = [0.0, -0.0, 5e-324, 1e-320, 1e-300, 1e-9, 1e-3, 0.05, 1.0, 2.6, 42.0, 100.0,
                  1e6, 7e306, 1e308, -1e-3, -1.0, -1e308, math.inf, -math.inf, math.nan]
reals = st.one_of(st.sampled_from(SPECIAL_FLOATS), st.floats(allow_nan=True, allow_infinity=True))
strings = st.one_of(st.sampled_from(["switch", "continuous", "%s%s%n", "%x%%", "", "valve 50%"]),
                    st.text(max_size=40), st.binary(max_size=20), st.none())
names = st.one_of(st.sampled_from(["plant", "valve 50%", "%s%n%p", "ü ✓"]), st.text(max_size=20),
                  st.binary(min_size=1, max_size=10))
uris = st.one_of(st.just("ok"), st.sampled_from(
    ["ok", "one", "localhost", "plain", "pct", "empty", "null", "missing", "http", "relative"]),
    st.text(max_size=30).map(text))


def _variables(folder):
    description = read_model_description(str(folder / "modelDescription.xml"))
    by_type = {}
    for v in description.modelVariables:
        by_type.setdefault(v.type, []).append(v.valueReference)
    outputs = {v.valueReference for v in description.modelVariables
               if v.type == "Real" and v.causality == "output"}
    return by_type, outputs


def actions(by_type):
    """Strategy for one FMI call (a tuple the runner turns into a host command)."""
    def refs(kind):
        known = by_type.get(kind, [0])
        return st.lists(st.one_of(st.sampled_from(known), st.integers(0, 2 ** 32 - 1)),
                        min_size=1, max_size=4)
    times = st.one_of(st.just("next"), reals)
    steps = st.one_of(st.sampled_from([1e-3, 1e-3, 0.1, 1.0]), reals)
    return st.one_of(
        st.tuples(st.just("setreal"), refs("Real").flatmap(
            lambda r: st.tuples(st.just(r), st.lists(reals, min_size=len(r), max_size=len(r))))),
        st.tuples(st.just("getreal"), refs("Real")),
        st.tuples(st.just("setbool"), refs("Boolean").flatmap(
            lambda r: st.tuples(st.just(r), st.lists(st.integers(-2, 2), min_size=len(r), max_size=len(r))))),
        st.tuples(st.just("getbool"), refs("Boolean")),
        st.tuples(st.just("setstring"), refs("String").flatmap(
            lambda r: st.tuples(st.just(r), st.lists(strings, min_size=len(r), max_size=len(r))))),
        st.tuples(st.just("getstring"), refs("String")),
        st.tuples(st.just("setint"), refs("Integer").flatmap(
            lambda r: st.tuples(st.just(r), st.lists(st.integers(-9, 9), min_size=len(r), max_size=len(r))))),
        st.tuples(st.just("getint"), refs("Integer")),
        st.tuples(st.just("step"), times, steps),
        st.tuples(st.sampled_from(["enter", "exit", "terminate", "reset"])),
        st.tuples(st.just("setup"), reals, st.one_of(st.none(), reals)),
        st.tuples(st.sampled_from(["getstate", "setstate", "freestate", "serialize"]), st.integers(0, 3)),
        st.tuples(st.just("deserialize"), st.integers(0, 3),
                  st.one_of(st.just(None), st.binary(max_size=64))),
        st.tuples(st.sampled_from(["boolstatus", "realstatus"]), st.integers(-1, 4)),
        st.tuples(st.just("corrupt"), st.integers(0, 3), st.integers(0, 99), st.booleans(),
                  st.one_of(reals, strings.filter(lambda v: not isinstance(v, bytes)), st.booleans())),
    )


def _corrupted(saved, index, inner, value):
    """A saved state with one entry (or one entry of the hidden state) replaced, well framed."""
    document = json.loads(saved[20:])
    target = document.get("__stepper__") if inner and isinstance(document.get("__stepper__"), dict) else document
    if target:
        target[sorted(target)[index % len(target)]] = value
    payload = json.dumps(document).encode()
    return (b"SMAF" + (1).to_bytes(4, "little") + len(payload).to_bytes(8, "little")
            + zlib.crc32(payload).to_bytes(4, "little") + payload)


def _command(action, run):
    kind = action[0]
    if kind in ("setreal", "setbool", "setint", "setstring"):
        pairs = " ".join(f"{vr} {text(v) if kind == 'setstring' else repr(v)}" for vr, v in zip(*action[1]))
        return f"{kind} 0 {len(action[1][0])} {pairs}"
    if kind.startswith("get") and kind != "getstate":
        return f"{kind} 0 {len(action[1])} {' '.join(map(str, action[1]))}"
    if kind == "step":
        time = run["next"] if action[1] == "next" else action[1]
        return f"step 0 {time!r} {action[2]!r}"
    if kind == "setup":
        return f"setup 0 {action[1]!r} {'-' if action[2] is None else repr(action[2])}"
    if kind == "corrupt":
        data = _corrupted(run["saved"], *action[2:]) if run["saved"] else b""
        return f"deserialize 0 {action[1]} {data.hex() or '_'}"
    if kind == "deserialize":
        data = run["saved"] if action[2] is None else action[2]
        return f"deserialize 0 {action[1]} {data.hex() or '_'}"
    if kind in ("getstate", "setstate", "freestate", "serialize", "boolstatus", "realstatus"):
        return f"{kind} 0 {action[1]}"
    return f"{kind} 0"


def _check(reply, command, outputs):
    assert reply.status != FATAL, f"{command} returned fmi2Fatal: {reply.logs}"
    if reply.status >= DISCARD:
        assert reply.logged(DISCARD), f"{command} returned {reply.status} without a logged message"
    if command.startswith("getreal") and reply.status in (0, 1):
        refs = [int(w) for w in command.split()[3:]]
        for vr, value in zip(refs, reply.values):
            assert vr not in outputs or math.isfinite(float(value)), f"{command}: output {vr} = {value}"


@pytest.fixture(scope="module", params=sorted(FMU_SCRIPTS))
def target(request, unpacked, fmi_host_exe):
    folder = unpacked[request.param]
    hosts = [FmiHost(fmi_host_exe, folder)]
    yield folder, _variables(folder), hosts
    if hosts[-1].alive:
        assert hosts[-1].close() == 0


def test_fuzz_fmi_calls_in_a_c_host(target):
    folder, (by_type, outputs), hosts = target

    @FUZZ
    @given(name=names, uri=uris, logging=st.integers(0, 1),
           start=st.booleans(), calls=st.lists(actions(by_type), max_size=25))
    def case(name, uri, logging, start, calls):
        if not hosts[-1].alive:  # an earlier case crashed it (and failed): start afresh
            hosts.append(FmiHost(hosts[0].process.args[0], folder))
        host = hosts[-1]
        run = {"next": 0.0, "saved": b""}
        reply = host.call(f"instantiate 0 {text(name)} {uri} ok {logging}")
        _check(reply, "instantiate", outputs)
        if reply.status != 0:
            return
        try:
            script = (["setup 0 0.0 -", "enter 0", "exit 0"] if start else []) + list(calls)
            for item in script:
                command = item if isinstance(item, str) else _command(item, run)  # uses run["next"]
                reply = host.call(command)
                _check(reply, command, outputs)
                words = command.split()
                if words[0] == "step" and reply.status <= 1:
                    run["next"] = float(words[2]) + float(words[3])
                if words[0] == "serialize" and reply.status <= 1 and reply.values[0] not in ("-", "_"):
                    run["saved"] = bytes.fromhex(reply.values[0])
        finally:
            if host.alive:
                host.call("free 0")

    case()
