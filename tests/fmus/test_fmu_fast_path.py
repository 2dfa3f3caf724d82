"""The front's fast path (fmi2Set/Get served in C in stepComplete) refuses what the guard refuses.

Every call is made twice: with the fast path and without it (SMA_FMU_NO_FAST_PATH=1, read
when an instance is created): same status, same messages, same values afterwards.
"""
import math
from ctypes import c_double, c_int, c_size_t, c_uint, c_void_p

import pytest

from fmu_signals import STEP
from switched_runs import run_switched, same
from sma_fmu.fmi.driving.instance import FmuInstance

OK, ERROR = 0, 3
_TYPES = {"Real": c_double, "Integer": c_int, "Boolean": c_int}


def _call(fmu, function, kind, references, values=None):
    """(status, values read, messages logged) of fmi2<function><kind>(references, values)."""
    raw = fmu.library[f"fmi2{function}{kind}"]
    raw.restype = c_int
    ctype = _TYPES[kind]
    array = (ctype * len(references))(*(values or [0] * len(references)))
    seen = len(fmu.messages)
    status = raw(c_void_p(fmu.component), (c_uint * len(references))(*references),
                 c_size_t(len(references)), array)
    return status, list(array), [text for _, text in fmu.messages[seen:]]


def _refs(fmu, *names):
    return [fmu.variables[name].valueReference for name in names]


def _state(fmu):
    """Every Real, Integer and Boolean value (read through the front)."""
    values = {}
    for kind in _TYPES:
        names = [n for n, v in fmu.variables.items() if v.type == kind]
        values.update(zip(names, _call(fmu, "Get", kind, _refs(fmu, *names))[1]))
    return values


def _script(fmu):
    """The calls, in stepComplete and after fmi2Terminate; (status, values, messages) of each."""
    P_in, load, R, T_start, mode, heating = _refs(fmu, "P_in", "load", "R", "T_start",
                                                  "hysteresis_mode", "heating")
    calls = [
        ("Set", "Real", [R], [1.0]),                    # an output
        ("Set", "Real", [T_start], [30.0]),             # a fixed parameter after initialization
        ("Set", "Real", [999], [1.0]),                  # no such variable
        ("Set", "Real", [P_in, R], [2.5, 1.0]),         # all or nothing: P_in stays
        ("Set", "Real", [P_in, load], [math.nan, 0.05]),  # accepted (the step discards it)
        ("Set", "Real", [P_in], [1.5]),                 # accepted
        ("Get", "Real", [P_in, R, 999], None),          # NaN for 999, fmi2Error
        ("Set", "Integer", [mode], [2]),                # fixed
        ("Set", "Integer", [P_in], [1]),                # not an Integer
        ("Get", "Integer", [P_in], None),
        ("Set", "Boolean", [heating], [1]),             # an output
        ("Get", "Boolean", [heating, 999], None),
        ("Get", "Integer", [mode], None),
        ("Get", "Boolean", [heating], None),
    ]
    results = [_call(fmu, *call) for call in calls]
    fmu.step(3 * STEP, STEP)
    results.append(_state(fmu))
    state = fmu.get_state()
    results.append(_call(fmu, "Set", "Real", [P_in], [0.5]))
    fmu.set_state(state)                                 # the restore brings P_in = 1.5 back
    fmu.free_state(state)
    results.append(_call(fmu, "Get", "Real", [P_in], None))
    fmu._fmu.terminate()
    results.append(_call(fmu, "Set", "Real", [P_in], [1.0]))   # illegal after fmi2Terminate
    results.append(_call(fmu, "Get", "Real", [P_in, R], None))
    return results


def _warm(fmu):
    for k in range(3):
        _call(fmu, "Set", "Real", _refs(fmu, "P_in", "load"), [0.8, 0.05])
        fmu.step(k * STEP, STEP)


def _run(fmus, monkeypatch, fast):
    return run_switched(fmus, monkeypatch, "SMA_FMU_NO_FAST_PATH", fast, _script, warm=_warm)


def test_every_refused_call_is_refused_through_the_fast_path(fmus, monkeypatch):
    fast, slow = _run(fmus, monkeypatch, True), _run(fmus, monkeypatch, False)
    assert len(fast) == len(slow)
    for index, (a, b) in enumerate(zip(fast, slow)):
        assert same(a, b), f"call {index}: fast path {a!r}, guard {b!r}"
    statuses = [result[0] for result in fast if isinstance(result, tuple)]
    assert statuses.count(ERROR) >= 10 and OK in statuses
    refused = [result for result in fast if isinstance(result, tuple) and result[0] == ERROR]
    assert all(messages for _, _, messages in refused)  # each refusal says why
    assert fast[-2][0] == ERROR and "illegal call in state 'terminated'" in fast[-2][2][0]
    assert fast[-3][1] == [1.5]  # the restored P_in


def test_the_fast_path_serves_stepcomplete_without_python(fmus):
    """Served in C: a set and a get of known variables log nothing and touch no Python."""
    import gc
    with FmuInstance(fmus["SmaActuator"], "plant", {"load": 0.05}) as fmu:
        fmu.step(0.0, STEP)
        gc.collect()
        slave = next(o for o in gc.get_objects() if type(o).__name__ == "SmaActuator"
                     and getattr(o, "instance_name", None) == "plant")
        calls = []
        slave.set_real = slave.get_real = lambda *args: calls.append(args)
        P_in, T = _refs(fmu, "P_in", "T")
        assert _call(fmu, "Set", "Real", [P_in], [2.0])[0] == OK
        assert _call(fmu, "Get", "Real", [P_in, T], None)[1][0] == 2.0
        assert calls == []
        fmu.step(STEP, STEP)
        assert slave.P_in == 2.0  # the step took the input over
