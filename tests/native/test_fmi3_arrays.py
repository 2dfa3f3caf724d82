"""The plant's reversal stack as FMI 3.0 arrays (issue 39): SmaActuator's Float64 outputs
reversal_T [degC] and reversal_xi_MF [1], memory_depth values each (a UInt64 structural
parameter, set in Configuration Mode), and reversal_count, the entries in use.

Read through fmpy's FMU3Slave along random power walks with reversals, the arrays hold the
Python runtime's stack (PlantStepper.reversals, oldest first) bit for bit, NaN past it;
memory_depth sets the array length the description's <Dimension> names and getFloat64
takes; a wrong nValues, a set outside Configuration Mode or out of bounds gets fmi3Error
naming the variable.
"""
import math
import random

import pytest

from fmi3_twins import Instance3
from fmu_signals import plant_walk
from sma_fmu.runtime.parameters import MAX_MEMORY_DEPTH
from sma_fmu.runtime.plant import PlantStepper

pytestmark = pytest.mark.needs("gcc")

MODES = {1: "continuous", 2: "switch"}


@pytest.fixture(scope="module")
def actuator3(tmp_path_factory):
    from sma_fmu.fmi.packaging.fmi3_build import build_fmi3_fmus
    return build_fmi3_fmus(tmp_path_factory.mktemp("fmi3_arrays"), names=["SmaActuator"])["SmaActuator"]


def _stack(instance, depth):
    """(reversal_T, reversal_xi_MF, reversal_count) read in one getFloat64 of 2 depth values."""
    refs = [instance.variables[name].valueReference for name in ("reversal_T", "reversal_xi_MF")]
    status, values = instance.call("getFloat64", refs, nValues=2 * depth)
    assert status == 0, instance.log[-1:]
    status, count = instance.get("reversal_count")
    assert status == 0, instance.log[-1:]
    return values[:depth], values[depth:], count


@pytest.mark.parametrize("mode,depth", [(1, 5), (1, 64), (2, 4)])
def test_the_arrays_are_the_runtime_stack(actuator3, params, mode, depth):
    rng = random.Random(390 + depth)
    fmu = Instance3(actuator3, f"arrays-{mode}-{depth}")
    try:
        assert fmu.start({"hysteresis_mode": mode, "memory_depth": depth, "load": 0.2}) == 0
        plant = PlantStepper(params.replace(memory_depth=depth), mode=MODES[mode], load=0.2)
        counts, time = set(), 0.0
        for values in plant_walk(rng, 6000):
            for name, value in values.items():
                assert fmu.set(name, value) == 0
            assert fmu.step(time, 1e-3) <= 1, fmu.log[-1:]
            plant.step(values["P_in"], values["load"], 1e-3)
            time += 1e-3
            temperatures, fractions, count = _stack(fmu, depth)
            stack = plant.reversals
            assert count == len(stack)
            assert temperatures[:count] == [point[0] for point in stack]  # bit for bit
            assert fractions[:count] == [point[1] for point in stack]
            assert all(math.isnan(v) for v in temperatures[count:] + fractions[count:])
            assert fmu.get("R") == (0, plant.outputs.R)
            counts.add(count)
        if mode == 1:  # the walk reverses often enough to fill a small memory
            assert len(counts) > 2 and max(counts) >= min(depth - 1, 4)
        else:          # the switch mode keeps no reversals
            assert counts == {0}
    finally:
        fmu.close()


def test_memory_depth_sizes_the_arrays(actuator3):
    fmu = Instance3(actuator3, "sizes")
    try:
        variables = fmu.variables
        depth = variables["memory_depth"]
        assert depth.causality == "structuralParameter" and depth.type == "UInt64"
        for name in ("reversal_T", "reversal_xi_MF"):
            dimensions = variables[name].dimensions
            assert [d.valueReference for d in dimensions] == [depth.valueReference]
            assert variables[name].shape == (int(depth.start),) == (64,)
        assert fmu.get("memory_depth") == (0, 64)
        assert fmu.start({"memory_depth": 7}) == 0
        assert fmu.get("memory_depth") == (0, 7)
        assert fmu.step(0.0, 1e-3) == 0
        status, values = fmu.array("reversal_T")  # sized by what the FMU reports: 7
        assert status == 0 and len(values) == 7 and all(math.isnan(v) for v in values)
        # a wrong size: fmi3Error naming the array and its length, nothing read
        for wrong in (6, 8, 64):
            assert fmu.array("reversal_T", wrong)[0] == 3
            assert ("fmi3GetFloat64: nValues = %d, but the 1 value references take 7 values; "
                    "reversal_T is an array of 7 (its length is memory_depth)" % wrong
                    in fmu.log[-1][1])
        refs = [variables[n].valueReference for n in ("R", "reversal_xi_MF", "T")]
        assert fmu.call("getFloat64", refs, nValues=3)[0] == 3
        assert "take 9 values; reversal_xi_MF is an array of 7" in fmu.log[-1][1]
        status, values = fmu.call("getFloat64", refs, nValues=9)
        assert status == 0 and values[0] == fmu.get("R")[1] and values[8] == fmu.get("T")[1]
        time = variables["time"].valueReference
        status, values = fmu.call("getFloat64", [time, refs[1]], nValues=8)
        assert status == 0 and values[0] == 1e-3 and all(math.isnan(v) for v in values[1:])
    finally:
        fmu.close()


def test_memory_depth_is_set_in_configuration_mode_alone(actuator3):
    fmu = Instance3(actuator3, "structural")
    try:
        # outside Configuration Mode, out of bounds, as another type: refused, named
        assert fmu.set("memory_depth", 5) == 3
        assert "memory_depth (value reference" in fmu.log[-1][1]
        assert "only in Configuration Mode" in fmu.log[-1][1]
        assert fmu.call("enterConfigurationMode")[0] == 0
        ref = fmu.variables["memory_depth"].valueReference
        for bad in (0, 1, MAX_MEMORY_DEPTH + 1, 2 ** 63):
            assert fmu.set("memory_depth", bad) == 3
            assert f"memory_depth (value reference {ref}) cannot be set: {bad} is outside " \
                   f"[2, {MAX_MEMORY_DEPTH}]" in fmu.log[-1][1]
        assert fmu.call("setInt32", [ref], [5])[0] == 3
        assert "UInt64 variable memory_depth, not an Int32" in fmu.log[-1][1]
        assert fmu.set("T_start", 20.0) == 3  # only the structural parameter in this mode
        assert "only the structural parameter memory_depth" in fmu.log[-1][1]
        assert fmu.call("enterInitializationMode")[0] == 3
        assert fmu.set("memory_depth", 2) == 0
        assert fmu.call("exitConfigurationMode")[0] == 0
        assert fmu.call("exitConfigurationMode")[0] == 3
        assert fmu.get("memory_depth") == (0, 2)
        # the outputs cannot be set; Configuration Mode only from Instantiated
        assert fmu.set("reversal_count", 1) == 3 and "it is an output" in fmu.log[-1][1]
        assert fmu.call("setFloat64", [fmu.variables["reversal_T"].valueReference],
                        [1.0, 2.0])[0] == 3
        assert "reversal_T (value reference" in fmu.log[-1][1]
        assert fmu.start() == 0
        assert fmu.call("enterConfigurationMode")[0] == 3
        assert fmu.set("memory_depth", 5) == 3 and fmu.get("memory_depth") == (0, 2)
        # the depth is the runtime's: two points at most
        for k, power in enumerate([2.0, 0.0, 1.5, 0.2, 1.2, 0.4] * 3):
            fmu.set("P_in", power)
            for j in range(300):
                assert fmu.step((k * 300 + j) * 1e-3, 1e-3) <= 1
            assert fmu.get("reversal_count")[1] <= 2
        assert fmu.call("reset")[0] == 0
        assert fmu.get("memory_depth") == (0, 64)  # back to its start
    finally:
        fmu.close()


def test_the_other_models_have_no_configuration_mode(tmp_path):
    from sma_fmu.fmi.packaging.fmi3_build import build_fmi3_fmus
    path = build_fmi3_fmus(tmp_path, names=["SmaPiController"])["SmaPiController"]
    fmu = Instance3(path, "pi-structural")
    try:
        assert fmu.call("enterConfigurationMode")[0] == 3
        assert "it has no structural parameters" in fmu.log[-1][1]
        assert fmu.call("getUInt64", [0])[0] == 3
        assert "value reference 0 is Float64 variable" in fmu.log[-1][1]
    finally:
        fmu.close()


def test_saved_states_replay_the_arrays(actuator3):
    """A state taken mid-walk, set and deserialized, replays the arrays bit for bit (NaN
    compared by repr)."""
    rng = random.Random(3939)
    inputs = plant_walk(rng, 3000)
    fmu = Instance3(actuator3, "arrays-states")
    try:
        assert fmu.start({"memory_depth": 6, "load": 0.2}) == 0

        def walk(first, last):
            seen = []
            for k in range(first, last):
                for name, value in inputs[k].items():
                    fmu.set(name, value)
                assert fmu.step(k * 1e-3, 1e-3) <= 1
                seen.append(repr(_stack(fmu, 6)))
            return seen

        walk(0, 2000)
        state = fmu.fmu.getFMUState()
        blob = fmu.fmu.serializeFMUState(state)
        first = walk(2000, 3000)
        assert len(set(first)) > 3  # the stack changes along the way
        fmu.fmu.setFMUState(state)
        assert walk(2000, 3000) == first
        fmu.fmu.setFMUState(fmu.fmu.deserializeFMUState(blob))
        assert walk(2000, 3000) == first
        fmu.fmu.freeFMUState(state)
    finally:
        fmu.close()
