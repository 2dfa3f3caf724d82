"""The C family's fuzz cases through both fronts: each call goes to an FMI 2.0 instance
(native_twins.Instance) and to its FMI 3.0 twin (fmi3_twins.Instance3) of the same model;
both must answer with the same status, and a refusal (discard or error) must come with a
logged message in both, naming the same variables.

The cases: the refusals the native equivalence and fuzz findings pinned (illegal calls per
state, bad parameters refusing initialization (R_M, l_F of 1e30 among them: outside their
plausible ranges), absurd loads, non-finite inputs, steps off
the time line) and random call sequences over every scalar variable with the fuzz suite's
special values (tests/fmus/test_fmu_fuzz.py's SPECIAL_FLOATS); and, FMI 3.0 only, the plant's
arrays read with good and wrong sizes (array_cases). Used in-process by
tests/native/test_fmi3_fuzz.py and, on binaries built with AddressSanitizer and UBSan, in a child
process by tests/native/test_native_sanitizers.py (``python fmi3_fuzz_cases.py FMI2_DIR FMI3_DIR``).
"""
import math
import random
import re
import sys

from fmi3_twins import Instance3
from native_twins import Instance

__all__ = ["SPECIAL_FLOATS", "Pair", "pinned_cases", "random_cases", "run_all", "array_cases"]

SPECIAL_FLOATS = [0.0, -0.0, 5e-324, 1e-320, 1e-300, 1e-9, 1e-3, 0.05, 1.0, 2.6, 42.0, 100.0,
                  1e6, 7e306, 1e308, -1e-3, -1.0, -1e308, math.inf, -math.inf, math.nan]
MODELS = ["SmaActuator", "SmaFeedforward", "SmaPiController", "SmaPwmDriver",
          "SmaScenarioSignals"]


class Pair:
    """One model as FMI 2.0 (``v2``) and FMI 3.0 (``v3``); ``calls``/``refused`` count."""

    def __init__(self, fmi2_path, fmi3_path, tag):
        self.v2 = Instance(fmi2_path, f"{tag}-v2")
        self.v3 = Instance3(fmi3_path, f"{tag}-v3")
        self.names = [n for n, v in self.v2.variables.items()]
        self.calls = self.refused = self.named = 0  # named: refusals naming a variable

    def _named(self, side):
        """The variables the last message of ``side`` names (whole words)."""
        text = side.log[-1][1] if side.log else ""
        return {n for n in self.names if re.search(rf"(?<![\w.]){re.escape(n)}(?![\w(])", text)}

    def same(self, what, statuses):
        """Both statuses equal; a refusal logged by both, naming the same variables."""
        self.calls += 1
        assert statuses[0] == statuses[1], (what, statuses, self.v2.log[-1:], self.v3.log[-1:])
        if statuses[0] >= 2:
            self.refused += 1
            assert self.v2.log and self.v3.log, what
            named = self._named(self.v2)
            assert named == self._named(self.v3), (what, self.v2.log[-1], self.v3.log[-1])
            self.named += bool(named)
        return statuses[0]

    def set(self, name, value):
        return self.same(("set", name, value), [self.v2.set(name, value), self.v3.set(name, value)])

    def get(self, name):
        return self.same(("get", name), [self.v2.get(name)[0], self.v3.get(name)[0]])

    def step(self, time, step):
        return self.same(("step", time, step), [self.v2.step(time, step), self.v3.step(time, step)])

    def enter(self, start_time=0.0):
        first = self.v2.call("setupExperiment", startTime=start_time)[0]
        second = self.v2.call("enterInitializationMode")[0] if first < 2 else first
        return self.same(("enter",), [max(first, second),
                                      self.v3.call("enterInitializationMode", startTime=start_time)[0]])

    def call(self, method):
        return self.same((method,), [self.v2.call(method)[0], self.v3.call(method)[0]])

    def close(self):
        self.v2.close()
        self.v3.close()


def _settable(pair):
    """The scalar variables the random cases set: all but the plant's structural
    memory_depth (FMI 3.0 sets it in Configuration Mode alone: tests/native/test_fmi3_arrays.py)."""
    return [n for n, v in pair.v2.variables.items()
            if not (n == "memory_depth" and pair.v3.variables[n].causality == "structuralParameter")]


def _value(rng, variable):
    if variable.type == "Real":
        return rng.choice(SPECIAL_FLOATS + [rng.uniform(-2.0, 2.0), rng.uniform(0.0, 100.0)])
    if variable.type == "Integer":
        return rng.randint(-2, 4)
    if variable.type == "Boolean":
        return rng.random() < 0.5
    return rng.choice(["", "switch", "continuous", "%s%n", "valve 50%", "ü ✓", "step"])


def pinned_cases(pair, model):
    """The pinned refusals, in order; every one must be refused alike."""
    refusals = pair.refused
    pair.get(pair.v2.outputs[0])                         # instantiated: no outputs yet
    pair.step(0.0, 1e-3)                                 # instantiated: no step
    pair.call("exitInitializationMode")                  # not in Initialization Mode
    pair.set(pair.v2.outputs[0], 1.0) if pair.v2.variables[pair.v2.outputs[0]].type == "Real" \
        else None                                        # an output
    assert pair.enter() == 0
    if model == "SmaActuator":
        for name, value in (("R_P", -33.0), ("stress_max", math.nan), ("T_start", -300.0),
                            ("R_M", 1e30), ("R_F", 1.7976931348623157e308), ("l_F", 1e30),
                            ("a_h", -1e30), ("stress_max", math.inf)):  # out of range
            pair.set(name, value)
            assert pair.call("exitInitializationMode") == 3  # refused, naming the parameter
            pair.get("R")                                     # outputs undefined
            pair.set(name, pair.v2.variables[name].start and float(pair.v2.variables[name].start))
        pair.set("hysteresis_mode", 3)
        assert pair.call("exitInitializationMode") == 3
        pair.set("hysteresis_mode", 1)
    assert pair.call("exitInitializationMode") == 0
    if model in ("SmaActuator", "SmaFeedforward"):
        time = 0.0
        for value in (math.nan, -0.5, 1e307, math.inf):      # absurd loads: discarded, named
            pair.set("load", value)
            assert pair.step(time, 1e-3) in (1, 2)
            pair.set("load", 0.1)
            assert pair.step(time, 1e-3) <= 1
            time += 1e-3
        if model == "SmaActuator":
            for value in (math.nan, 1e307):                   # non-finite power, overflow
                pair.set("P_in", value)
                assert pair.step(time, 1e-3) == 2
                pair.set("P_in", 0.2)
                assert pair.step(time, 1e-3) <= 1
                time += 1e-3
        pair.step(time + 0.5, 1e-3)                          # does not follow the last step
        pair.step(time, 0.0)                                 # no step size
        pair.step(time, -1e-3)
    start = pair.v2.variables.get("T_start") or next(
        (v for v in pair.v2.variables.values() if v.causality == "parameter"
         and v.variability == "fixed"), None)
    if start is not None and start.type == "Real":
        assert pair.set(start.name, 1.0) == 3                 # fixed, after initialization
    assert pair.call("terminate") == 0
    pair.step(0.0, 1e-3)                                      # terminated
    pair.call("terminate")
    assert pair.call("reset") == 0
    return pair.refused - refusals


def random_cases(pair, rng, count):
    """``count`` random calls; the next step time follows the last accepted one mostly."""
    settable, outputs = _settable(pair), pair.v2.outputs
    time = 0.0
    for _ in range(count):
        kind = rng.random()
        if kind < 0.35:
            name = rng.choice(settable)
            pair.set(name, _value(rng, pair.v2.variables[name]))
        elif kind < 0.55:
            pair.get(rng.choice(outputs + settable))
        elif kind < 0.85:
            at = time if rng.random() < 0.85 else rng.choice(SPECIAL_FLOATS)
            step = rng.choice([1e-3, 1e-3, 1e-3, 0.1, rng.choice(SPECIAL_FLOATS)])
            if pair.step(at, step) <= 1:
                time = at + step
        elif kind < 0.9:
            if pair.enter() == 0:
                time = 0.0
        elif kind < 0.96:
            pair.call("exitInitializationMode")
        elif kind < 0.98:
            pair.call("terminate")
        else:
            if pair.call("reset") == 0:
                time = 0.0


def run_all(fmi2_paths, fmi3_paths, seed=39, count=400):
    """Every model's pinned and random cases; {model: (calls, refused, refusals naming a
    variable)}."""
    found = {}
    for model in MODELS:
        pair = Pair(fmi2_paths[model], fmi3_paths[model], f"fuzz-{model}")
        try:
            pinned = pinned_cases(pair, model)
            assert pinned >= 3, (model, pinned)
            random_cases(pair, random.Random(f"{seed}-{model}"), count)
        finally:
            pair.close()
        found[model] = (pair.calls, pair.refused, pair.named)
    return found


def array_cases(fmi3_path, rng, steps=300):
    """The plant's arrays (FMI 3.0 only): Configuration Mode, good and wrong sizes along a
    walk with reversals; returns the number of array reads."""
    fmu = Instance3(fmi3_path, "fuzz-arrays")
    reads = 0
    try:
        assert fmu.start({"memory_depth": 3, "load": 0.1}) == 0
        refs = [fmu.variables[n].valueReference for n in ("reversal_T", "reversal_xi_MF")]
        for k in range(steps):
            fmu.set("P_in", 2.0 if (k // 40) % 2 == 0 else rng.uniform(0.0, 0.5))
            assert fmu.step(k * 1e-3, 1e-3) <= 1
            size = rng.choice([6, 6, 0, 1, 5, 7, 2 ** 20])
            status, _ = fmu.call("getFloat64", refs, nValues=size)
            assert status == (0 if size == 6 else 3), (size, fmu.log[-1:])
            reads += 1
    finally:
        fmu.close()
    return reads


if __name__ == "__main__":  # python fmi3_fuzz_cases.py FMI2_DIR FMI3_DIR [COUNT]
    from pathlib import Path
    folders = [Path(sys.argv[1]), Path(sys.argv[2])]
    paths = [{m: folder / f"{m}.fmu" for m in MODELS} for folder in folders]
    result = run_all(*paths, count=int(sys.argv[3]) if len(sys.argv) > 3 else 400)
    for model, (calls, refused, named) in result.items():
        print(f"{model}: {calls} calls, {refused} refused alike, {named} naming a variable")
    print(f"arrays: {array_cases(paths[1]['SmaActuator'], random.Random(39))} reads")
