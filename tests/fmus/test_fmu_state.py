"""FMU state: save at t = 5 s, run on, restore, rerun -> identical outputs (hidden state included)."""
import json
import math
import zlib

import pytest

from fmu_signals import STEP, plant_load, plant_power, reference
from sma_fmu.fmi.driving.instance import FmuError, FmuInstance
from sma_fmu.wire.parameter_file import load_parameters
from sma_fmu.runtime.plant import PlantStepper

SAVE_AT, RUN_TO = 5000, 8000  # steps: 5 s and 8 s


def _run(fmu, inputs, outputs, first, last):
    trace = []
    for k in range(first, last):
        fmu.set_real(inputs, inputs_at(inputs, k))
        fmu.step(k * STEP, STEP)
        trace.append(tuple(fmu.get_real(outputs)) + tuple(fmu.get_boolean(BOOLEANS[inputs])))
    return trace


def inputs_at(inputs, k):
    if inputs == ("P_in", "load"):
        return plant_power(k), plant_load(k)
    return reference(k), plant_load(k)


BOOLEANS = {("P_in", "load"): ["heating"], ("R_ref", "load"): ["saturated"]}
CASES = {
    "plant-continuous": ("SmaActuator", {"hysteresis_mode": 1},  # 1 = continuous
                         ("P_in", "load"), ("R", "T", "xi_P", "xi_M", "xi_F")),
    "plant-switch": ("SmaActuator", {}, ("P_in", "load"), ("R", "T", "x")),
    "feedforward": ("SmaFeedforward", {}, ("R_ref", "load"), ("P_ff", "T_ref")),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_restore_reruns_identically(fmus, case):
    name, start, inputs, outputs = CASES[case]
    with FmuInstance(fmus[name], case, start) as fmu:
        _run(fmu, inputs, outputs, 0, SAVE_AT)
        state = fmu.get_state()
        first = _run(fmu, inputs, outputs, SAVE_AT, RUN_TO)
        fmu.set_state(state)
        second = _run(fmu, inputs, outputs, SAVE_AT, RUN_TO)
        fmu.free_state(state)
    assert first == second
    assert len(set(first)) > 100  # the outputs really moved after the save point


@pytest.mark.parametrize("case", sorted(CASES))
def test_serialized_state_moves_to_a_fresh_instance(fmus, case):
    name, start, inputs, outputs = CASES[case]
    with FmuInstance(fmus[name], case + "-a", start) as source:
        _run(source, inputs, outputs, 0, SAVE_AT)
        data = source.serialize_state(source.get_state())
        expected = _run(source, inputs, outputs, SAVE_AT, SAVE_AT + 1000)
    with FmuInstance(fmus[name], case + "-b", start) as target:
        target.set_state(target.deserialize_state(data))
        assert _run(target, inputs, outputs, SAVE_AT, SAVE_AT + 1000) == expected


def _nested_power(k):
    """Power [W] with two superposed oscillations: nested minor loops, a deep stack."""
    t = k * STEP
    return max(0.0, plant_power(k) + 0.5 * math.sin(2.0 * math.pi * 2.3 * t))


def test_restored_stack_of_reversals_matters(fmus):
    """The FMU saves the plant's reversal stack; without it a restored plant would diverge,
    and a state in the format of an earlier build (one reversal) is refused."""
    probe = PlantStepper(load_parameters(), load=0.05)   # where is the stack two deep?
    save_at = next(k for k in range(SAVE_AT * 4) if len(probe.reversals) >= 2 and k > SAVE_AT
                   or probe.step(_nested_power(k), 0.05, STEP) is None)
    with FmuInstance(fmus["SmaActuator"], "memory", {}) as fmu:
        for k in range(save_at):
            fmu.set_real(("P_in", "load"), (_nested_power(k), 0.05))
            fmu.step(k * STEP, STEP)
        data = bytes(fmu.serialize_state(fmu.get_state()))
        document = json.loads(data[20:])                # after the front's header
        stack = document["__stepper__"]["reversals"]
        assert len(stack) >= 2
        expected = []
        for k in range(save_at, save_at + 2000):
            fmu.set_real(("P_in", "load"), (_nested_power(k), 0.05))
            fmu.step(k * STEP, STEP)
            expected.append(fmu.get_real(("R",))[0])
    runtime = PlantStepper(load_parameters(), load=0.05)
    runtime.restore(document["__stepper__"])         # the runtime reads what the FMU wrote
    forgetful = PlantStepper(load_parameters(), load=0.05)
    forgetful.restore({**document["__stepper__"], "reversals": []})
    powers = [_nested_power(k) for k in range(save_at, save_at + 2000)]
    assert [runtime.step(p, 0.05, STEP).R for p in powers] == pytest.approx(expected, abs=1e-12)
    assert max(abs(forgetful.step(p, 0.05, STEP).R - r) for p, r in zip(powers, expected)) > 0.1
    old = {**document, "__stepper__": {**{k: v for k, v in document["__stepper__"].items()
                                          if k not in ("format", "reversals")},
                                       "reversal": stack[-1]}}
    payload = json.dumps(old).encode()
    header = (b"SMAF" + (1).to_bytes(4, "little") + len(payload).to_bytes(8, "little")
              + zlib.crc32(payload).to_bytes(4, "little"))
    with FmuInstance(fmus["SmaActuator"], "old-state", {}) as fresh:
        with pytest.raises(FmuError, match="earlier sma-fmu build"):
            fresh.set_state(fresh.deserialize_state(header + payload))
