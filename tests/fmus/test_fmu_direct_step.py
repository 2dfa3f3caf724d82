"""The front's direct fmi2DoStep (model-free checks in C, the slave's step called without
pythonfmu) refuses, discards and reports exactly what pythonfmu's route does.

Every doStep is made twice: with the direct step and without it (SMA_FMU_NO_DIRECT_STEP=1,
read when an instance is created): same status, messages, fmi2LastSuccessfulTime,
fmi2Terminated and outputs.
"""
import math
from ctypes import byref, c_double, c_int, c_size_t, c_uint, c_void_p

from fmu_signals import STEP
from switched_runs import run_switched, same
from sma_fmu.fmi.driving.instance import FmuInstance

OK, DISCARD, ERROR = 0, 2, 3
LAST_SUCCESSFUL_TIME, TERMINATED = 2, 3  # fmi2StatusKind
STOP = 8 * STEP


def _raw(fmu, name):
    function = fmu.library[name]
    function.restype = c_int
    return function


def _set_real(fmu, name, value):
    reference = (c_uint * 1)(fmu.variables[name].valueReference)
    return _raw(fmu, "fmi2SetReal")(c_void_p(fmu.component), reference, c_size_t(1),
                                    (c_double * 1)(value))


def _step(fmu, t, h):
    """(status, messages, last successful time, terminated, R, T) of fmi2DoStep(t, h)."""
    seen = len(fmu.messages)
    status = _raw(fmu, "fmi2DoStep")(c_void_p(fmu.component), c_double(t), c_double(h), c_int(1))
    last, terminated = c_double(-1.0), c_int(-1)
    last_status = _raw(fmu, "fmi2GetRealStatus")(c_void_p(fmu.component), c_int(LAST_SUCCESSFUL_TIME),
                                                 byref(last))
    _raw(fmu, "fmi2GetBooleanStatus")(c_void_p(fmu.component), c_int(TERMINATED), byref(terminated))
    R, T = fmu.get_real(("R", "T"))
    return (status, [text for _, text in fmu.messages[seen:]], last_status, last.value,
            terminated.value, R, T)


def _script(fmu):
    """Good, refused and discarded steps of a run with stopTime = STOP."""
    fmu._fmu.reset()
    fmu._fmu.setupExperiment(startTime=0.0, stopTime=STOP)
    fmu._fmu.enterInitializationMode()
    fmu._fmu.exitInitializationMode()
    results = [_step(fmu, 0.0, STEP)]                          # done
    for t, h in ((math.nan, STEP), (STEP, 0.0), (STEP, math.inf), (STEP, -STEP),
                 (-math.inf, STEP), (0.5, STEP), (0.0, STEP)):  # refused: t, h, not following
        results.append(_step(fmu, t, h))
    results.append(_step(fmu, STEP * (1 + 1e-12), STEP))      # follows up to rounding: done
    results.append(_set_real(fmu, "P_in", math.nan))
    results.append(_step(fmu, 2 * STEP, STEP))                 # discarded by the model
    results.append(_step(fmu, 2 * STEP, STEP))                 # again: fmi2Terminated
    results.append(_set_real(fmu, "P_in", 1.5))
    for k in range(2, 6):
        results.append(_step(fmu, k * STEP, STEP))             # done
    results.append(_step(fmu, 6 * STEP, 3 * STEP))             # passes stopTime: refused
    results.append(_step(fmu, 6 * STEP, STOP - 6 * STEP + 1e-15))  # ends at stopTime: done
    results.append(_step(fmu, STOP, STEP))                     # passes stopTime: refused
    fmu._fmu.terminate()
    results.append(_step(fmu, STOP, 0.0))                      # after fmi2Terminate
    return results


def _run(fmus, monkeypatch, direct):
    return run_switched(fmus, monkeypatch, "SMA_FMU_NO_DIRECT_STEP", direct, _script,
                        cleared=("SMA_FMU_NO_FAST_PATH",))


def test_every_refused_or_discarded_step_is_reported_alike(fmus, monkeypatch):
    direct, pythonfmu = _run(fmus, monkeypatch, True), _run(fmus, monkeypatch, False)
    assert len(direct) == len(pythonfmu)
    for index, (a, b) in enumerate(zip(direct, pythonfmu)):
        assert same(a, b), f"call {index}: direct {a!r}, through pythonfmu {b!r}"
    steps = [r for r in direct if isinstance(r, tuple)]
    statuses = [r[0] for r in steps]
    assert statuses.count(ERROR) >= 9 and statuses.count(DISCARD) == 2 and statuses.count(OK) >= 6
    assert all(r[1] for r in steps if r[0] != OK)  # each refusal and discard says why
    discarded = [r for r in steps if r[0] == DISCARD]
    assert "P_in must be finite" in discarded[0][1][0] and discarded[1][4] == 1  # terminated
    assert all("passes stopTime" in steps[i][1][0] for i in (-4, -2))
    assert "illegal call in state" in steps[-1][1][0]
    assert steps[-3][0] == OK and steps[-3][3] == 6 * STEP + (STOP - 6 * STEP + 1e-15)


def test_a_good_step_bypasses_pythonfmu(fmus, monkeypatch):
    """An accepted step never goes through pythonfmu's do_step entry; a refused one does
    (the guard gives the message)."""
    import gc
    monkeypatch.delenv("SMA_FMU_NO_DIRECT_STEP", raising=False)
    monkeypatch.delenv("SMA_FMU_NO_FAST_PATH", raising=False)
    with FmuInstance(fmus["SmaActuator"], "direct", {"load": 0.05}) as fmu:
        fmu.step(0.0, STEP)
        gc.collect()
        slave = next(o for o in gc.get_objects() if type(o).__name__ == "SmaActuator"
                     and getattr(o, "instance_name", None) == "direct")
        entry, calls = slave.do_step, []
        slave.do_step = lambda *args: calls.append(args) or entry(*args)
        T_before = fmu.get_real(("T",))[0]
        assert _set_real(fmu, "P_in", 3.0) == OK
        assert _step(fmu, STEP, STEP)[0] == OK
        assert calls == [] and slave.P_in == 3.0 and fmu.get_real(("T",))[0] != T_before
        assert _step(fmu, 5 * STEP, STEP)[0] == ERROR  # not following: pythonfmu's route
        assert calls == [(5 * STEP, STEP)]


def _inputs_run(path, direct, monkeypatch, steps=400):
    """Every Real output after each of ``steps`` steps whose Real inputs follow the shared
    signals (a new value at most steps, none at some: both forms of the inputs)."""
    from fmu_signals import plant_power, reference
    if direct:
        monkeypatch.delenv("SMA_FMU_NO_DIRECT_STEP", raising=False)
    else:
        monkeypatch.setenv("SMA_FMU_NO_DIRECT_STEP", "1")
    monkeypatch.delenv("SMA_FMU_NO_FAST_PATH", raising=False)
    with FmuInstance(path, "inputs") as fmu:
        variables = list(fmu.variables.values())
        inputs = tuple(v.name for v in variables if v.causality == "input" and v.type == "Real")
        outputs = tuple(v.name for v in variables if v.causality == "output" and v.type == "Real")
        rows = []
        for k in range(steps):
            if inputs and k % 7 != 3:  # some steps take no new input
                values = [plant_power(k) if i == 0 else 20.0 + reference(k) + i for i in range(len(inputs))]
                fmu.set_real(inputs, values)
            fmu.step(k * STEP, STEP)
            rows.append(fmu.get_real(outputs))
        return outputs, rows, [text for status, text in fmu.messages if status != "ok"]


def test_every_fmu_steps_alike_with_and_without_the_direct_step(fmus, monkeypatch):
    """The five FMUs (three with the inlined step, two with the general one) give the same
    outputs, bit for bit, and the same warnings with the direct step as through pythonfmu."""
    for name, path in sorted(fmus.items()):
        names, direct, direct_log = _inputs_run(path, True, monkeypatch)
        _, pythonfmu, pythonfmu_log = _inputs_run(path, False, monkeypatch)
        assert names and direct == pythonfmu, name
        assert direct_log == pythonfmu_log, name
        assert len({tuple(row) for row in direct}) > 1, f"{name}: the outputs never moved"


def test_three_slaves_declare_the_step_the_front_inlines():
    """SmaActuator, SmaFeedforward and SmaPiController declare their stepper call (the direct
    step inlines it); the PWM driver and the signal source keep their own and get the
    general form."""
    import importlib
    from sma_fmu.fmi.models import declarations
    declared = {}
    for fmu in declarations():
        declared[fmu.name] = getattr(importlib.import_module(fmu.slave_module), fmu.name).declared_step
    assert {name for name, step in declared.items() if step} == {
        "SmaActuator", "SmaFeedforward", "SmaPiController"}
    assert declared["SmaActuator"][:2] == ("step", ("P_in", "load"))
    assert declared["SmaPiController"][:2] == ("sample", ("R", "R_ref", "P_ff"))
