"""The C family as FMI 3.0 co-simulation FMUs (issue 39): `sma-fmu build --native --fmi 3`.

Built from the same C models and core as FMI 2.0, under the FMI 3.0 front. fmpy validates
them; driven side by side with their FMI 2.0 twins through fmpy (FMU3Slave, FMU2Slave) on
random input walks, every output is equal (difference 0.0); saved states replay alike and a
corrupted one is refused; bad input gets the FMI 2.0 status and a message naming the same
variable, and the fmi3 function; calls outside their state and arrays of the wrong size get
fmi3Error.
"""
import random
import zipfile
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from fmi3_twins import Instance3
from fmu_signals import plant_walk
from native_twins import Instance
from test_native_equivalence import _reference_inputs
from sma_fmu.cli import main
from sma_fmu.runtime.reachable_band import reachable_band

pytestmark = pytest.mark.needs("gcc")

NAMES = ["SmaActuator", "SmaFeedforward", "SmaPiController", "SmaPwmDriver", "SmaScenarioSignals"]


class Versions:
    """One C-family model as FMI 2.0 (``v2``) and FMI 3.0 (``v3``)."""

    def __init__(self, native_fmus, fmi3_fmus, model, tag):
        self.v2 = Instance(native_fmus[model], f"{tag}-v2")
        self.v3 = Instance3(fmi3_fmus[model], f"{tag}-v3")

    def both(self, method, *args):
        results = [getattr(side, method)(*args) for side in (self.v2, self.v3)]
        statuses = [r[0] if isinstance(r, tuple) else r for r in results]
        assert statuses[0] == statuses[1], (method, args, self.v2.log[-1:], self.v3.log[-1:])
        return results

    def compare(self):
        """Every output of FMI 2.0 equal in FMI 3.0 (0.0 difference); returns those."""
        v2, v3 = self.v2.values(), self.v3.values(self.v2.outputs)
        assert v2 == v3
        return v3

    def walk(self, inputs, time=0.0, step=1e-3):
        seen = []
        for values in inputs:
            for name, value in values.items():
                self.both("set", name, value)
            assert self.both("step", time, step)[0] <= 1, self.v3.log[-2:]
            time += step
            seen.append(self.compare())
        return seen, time

    def close(self):
        self.v2.close()
        self.v3.close()


def test_fmpy_validates_them_and_they_are_fmi3(fmi3_fmus):
    from fmpy.validation import validate_fmu
    for name in NAMES:
        path = fmi3_fmus[name]
        assert validate_fmu(str(path)) == [], name
        with zipfile.ZipFile(path) as archive:
            files = set(archive.namelist())
            root = ET.fromstring(archive.read("modelDescription.xml"))
            build = ET.fromstring(archive.read("sources/buildDescription.xml"))
        assert root.get("fmiVersion") == "3.0" and root.get("instantiationToken")
        assert {f"binaries/x86_64-linux/{name}.so", f"binaries/x86_64-windows/{name}.dll",
                "resources/parameters.json"} <= files
        listed = {f.get("name") for f in build.iter("SourceFile")}
        assert listed and all(f"sources/{n}" in files for n in listed)
        assert not any(n.startswith("fmi2") for n in listed)
        time = [v for v in root.find("ModelVariables") if v.get("name") == "time"]
        assert time[0].get("causality") == "independent" and time[0].get("unit") == "s"
        kinds = {v.get("name"): v.tag for v in root.find("ModelVariables")}
        for choice in ("hysteresis_mode", "inverse"):
            assert kinds.get(choice, "Enumeration") == "Enumeration"
    assert sum(k == "Enumeration" for k in kinds.values()) == 0  # SmaScenarioSignals: none


def test_the_plant_has_terminals_valid_by_the_schema(fmi3_fmus):
    import os
    import fmpy
    from lxml import etree
    schema = etree.XMLSchema(file=os.path.join(os.path.dirname(fmpy.__file__), "schema", "fmi3",
                                               "fmi3TerminalsAndIcons.xsd"))
    with zipfile.ZipFile(fmi3_fmus["SmaActuator"]) as archive:
        root = etree.fromstring(archive.read("terminalsAndIcons/terminalsAndIcons.xml"))
    assert schema.validate(root), schema.error_log
    members = {t.get("name"): [m.get("variableName") for m in t] for t in root.iter("Terminal")}
    assert members == {"electrical": ["P_in", "R"], "thermal": ["T"], "mechanical": ["load", "x"]}
    with zipfile.ZipFile(fmi3_fmus["SmaPwmDriver"]) as archive:   # P_in out, R in (its limit)
        driver = etree.fromstring(archive.read("terminalsAndIcons/terminalsAndIcons.xml"))
    assert schema.validate(driver), schema.error_log
    assert {t.get("name"): [m.get("variableName") for m in t] for t in driver.iter("Terminal")} \
        == {"electrical": ["P_in", "R"]}
    with zipfile.ZipFile(fmi3_fmus["SmaPiController"]) as archive:
        assert not any(n.startswith("terminalsAndIcons/") for n in archive.namelist())


def test_binaries_export_only_fmi3_functions(fmi3_fmus, tmp_path):
    import shutil
    import subprocess
    if not shutil.which("nm"):
        pytest.skip("no nm")
    with zipfile.ZipFile(fmi3_fmus["SmaActuator"]) as archive:
        archive.extract("binaries/x86_64-linux/SmaActuator.so", tmp_path)
    out = subprocess.run(["nm", "-D", "--defined-only", str(tmp_path / "binaries/x86_64-linux/SmaActuator.so")],
                         capture_output=True, text=True, check=True).stdout
    exported = [line.split()[-1] for line in out.splitlines() if " T " in line]
    assert "fmi3DoStep" in exported and "fmi3GetFloat64" in exported
    assert all(name.startswith("fmi3") for name in exported), exported
    assert len(exported) == 75  # every function fmi3Functions.h declares, no fmi2 one


@pytest.mark.parametrize("mode", [1, 2])
def test_plant_walks_equal_fmi2(native_fmus, fmi3_fmus, mode):
    rng = random.Random(39 + mode)
    twins = Versions(native_fmus, fmi3_fmus, "SmaActuator", f"plant3-{mode}")
    try:
        start = {"hysteresis_mode": mode, "memory_depth": 3, "load": 0.2}
        assert twins.both("start", start) == [0, 0]
        twins.compare()
        inputs = plant_walk(rng, 6000)
        _, time = twins.walk(inputs[:4000])
        # saved states, taken in both versions: set and deserialized, they replay alike
        saved = (twins.v2.fmu.getFMUstate(), twins.v3.fmu.getFMUState())
        blobs = (twins.v2.fmu.serializeFMUstate(saved[0]), twins.v3.fmu.serializeFMUState(saved[1]))
        first, _ = twins.walk(inputs[4000:5000], time)
        twins.v2.fmu.setFMUstate(saved[0])
        twins.v3.fmu.setFMUState(saved[1])
        assert twins.walk(inputs[4000:5000], time)[0] == first
        twins.v2.fmu.setFMUstate(twins.v2.fmu.deSerializeFMUstate(blobs[0]))
        twins.v3.fmu.setFMUState(twins.v3.fmu.deserializeFMUState(blobs[1]))
        _, time = twins.walk(inputs[4000:5000], time)
        twins.walk(inputs[5000:], time)
    finally:
        twins.close()


def test_saved_states_replay_and_a_corrupted_one_is_refused(fmi3_fmus):
    rng = random.Random(3)
    inputs = plant_walk(rng, 1500)
    one = Instance3(fmi3_fmus["SmaActuator"], "states3")
    try:
        assert one.start({"memory_depth": 3, "load": 0.2}) == 0
        time = 0.0
        for values in inputs[:500]:
            for name, value in values.items():
                one.set(name, value)
            assert one.step(time, 1e-3) == 0
            time += 1e-3
        state = one.fmu.getFMUState()
        blob = one.fmu.serializeFMUState(state)

        def run():
            seen, t = [], time
            for values in inputs[500:]:
                for name, value in values.items():
                    one.set(name, value)
                assert one.step(t, 1e-3) == 0
                t += 1e-3
                seen.append(one.values())
            return seen

        first = run()
        one.fmu.setFMUState(state)
        assert run() == first
        one.fmu.setFMUState(one.fmu.deserializeFMUState(blob))
        assert run() == first
        bad = bytearray(blob)
        bad[len(bad) // 2] ^= 0xFF
        status, _ = one.call("deserializeFMUState", bytes(bad))
        assert status == 3
        assert one.log[-1][0] == 3 and "fmi3DeserializeFMUState: the bytes are refused" in one.log[-1][1]
        one.fmu.setFMUState(state)  # the refusal changed nothing: the state still replays
        assert run() == first
        one.fmu.freeFMUState(state)
    finally:
        one.close()


@pytest.mark.parametrize("inverse", [1, 2])
def test_compensator_walks_equal_fmi2(native_fmus, fmi3_fmus, params, inverse):
    rng = random.Random(11 * inverse)
    band = reachable_band(0.1, params)
    twins = Versions(native_fmus, fmi3_fmus, "SmaFeedforward", f"ff3-{inverse}")
    try:
        start = {"inverse": inverse, "memory_depth": 3, "R_ref": band.cold, "load": 0.1}
        assert twins.both("start", start) == [0, 0]
        twins.compare()
        twins.walk(_reference_inputs(rng, 5000, band))
    finally:
        twins.close()


@pytest.mark.parametrize("model,inputs", [
    ("SmaPiController", lambda rng: {"R": rng.uniform(35, 50), "R_ref": rng.uniform(35, 50),
                                     "P_ff": rng.uniform(0, 2)}),
    ("SmaPwmDriver", lambda rng: {"P_demand": rng.uniform(-0.5, 3.0)}),
    ("SmaScenarioSignals", lambda rng: {}),
])
def test_other_walks_equal_fmi2(native_fmus, fmi3_fmus, model, inputs):
    rng = random.Random(len(model))
    twins = Versions(native_fmus, fmi3_fmus, model, f"{model}-3")
    try:
        assert twins.both("start") == [0, 0]
        twins.compare()
        walk = []
        for k in range(4000):
            walk.append(inputs(rng) if k % rng.randint(1, 50) == 0 else {})
        twins.walk(walk)
    finally:
        twins.close()


def test_bad_input_and_refused_calls(native_fmus, fmi3_fmus):
    twins = Versions(native_fmus, fmi3_fmus, "SmaActuator", "bad3")
    try:
        # a call outside its state: fmi3Error naming the fmi3 function
        assert twins.v3.step(0.0, 1e-3) == 3
        assert "fmi3DoStep: illegal call in state 'instantiated'" in twins.v3.log[-1][1]
        assert twins.both("start", {"load": 0.2}) == [0, 0]
        # bad input: the FMI 2.0 status, the same variable named
        time = 0.0
        for name, value in (("P_in", float("nan")), ("load", -0.5), ("P_in", 1e307)):
            twins.both("set", name, value)
            assert twins.both("step", time, 1e-3) == [2, 2]
            texts = [side.log[-1][1].replace(side.name, "#") for side in (twins.v2, twins.v3)]
            assert texts[0] == texts[1] and (name in texts[1] or "temperature" in texts[1])
            twins.both("set", name, 0.2)
            assert twins.both("step", time, 1e-3) == [0, 0]
            time += 1e-3
        # the very same step discarded twice: terminateSimulation
        twins.both("set", "P_in", float("nan"))
        assert twins.v3.do_step(time, 1e-3) == (2, False, False, False, time)
        assert twins.v3.do_step(time, 1e-3) == (2, False, True, False, time)
        twins.both("set", "P_in", 0.5)
        # an array of the wrong size, a type that is not the variable's: fmi3Error
        vr = twins.v3.variables["R"].valueReference
        assert twins.v3.call("getFloat64", [vr], nValues=2)[0] == 3
        assert "fmi3GetFloat64: nValues = 2" in twins.v3.log[-1][1]
        mode = twins.v3.variables["hysteresis_mode"].valueReference
        assert twins.v3.call("getInt32", [mode])[0] == 3
        assert "Enumeration variable hysteresis_mode, not an Int32" in twins.v3.log[-1][1]
        assert twins.v3.call("getInt64", [mode]) == (0, [1])
        assert twins.v3.call("getFloat32", [vr])[0] == 3
        assert twins.v3.call("setFloat64", [twins.v3.variables["time"].valueReference], [1.0])[0] == 3
        assert twins.v3.call("getFloat64", [twins.v3.variables["time"].valueReference]) == (0, [time])
        # a fixed parameter after initialization: the FMI 2.0 refusal, in FMI 3.0's words
        assert twins.both("set", "T_start", 20.0) == [3, 3]
        assert "before fmi3ExitInitializationMode" in twins.v3.log[-1][1]
        assert all("fmi2" not in text for _, text in twins.v3.log)
    finally:
        twins.close()


def test_a_bad_resource_path_is_refused_in_fmi3_words(fmi3_fmus, tmp_path):
    from fmpy.fmi3 import (fmi3InstanceEnvironment, fmi3IntermediateUpdateCallback,
                           fmi3LogMessageCallback, fmi3ValueReference)
    one = Instance3(fmi3_fmus["SmaPwmDriver"], "resources3")
    try:
        callback = fmi3LogMessageCallback(one._logger)
        token = one.fmu.guid.encode()
        for where, words in ((b"relative/path/", "is not a file: URI"),
                             (str(tmp_path).encode() + b"/", "holds no parameters.json")):
            made = one.fmu.fmi3InstantiateCoSimulation(
                b"other", token, where, False, False, False, False, (fmi3ValueReference * 0)(), 0,
                fmi3InstanceEnvironment(), callback, fmi3IntermediateUpdateCallback())
            assert not made
            assert one.log[-1][0] == 3 and words in one.log[-1][1]
            assert "resourcePath" in one.log[-1][1] and "fmuResourceLocation" not in one.log[-1][1]
    finally:
        one.close()


def test_event_mode_without_events_changes_nothing(fmi3_fmus):
    """The plant in event mode: Event Mode after initialization, no discrete update, no
    event asked for; stepping as without event mode."""
    rng = random.Random(5)
    inputs = plant_walk(rng, 300)
    runs = []
    for events in (False, True):
        one = Instance3(fmi3_fmus["SmaActuator"], f"ev{events}", event_mode=events, early_return=events)
        try:
            assert one.start({"load": 0.2}) == 0
            if events:
                assert one.call("doStep", 0.0, 1e-3)[0] == 3 and "Event Mode" in one.log[-1][1]
                update = one.fmu.updateDiscreteStates()
                assert update[0] is False and update[4] is False  # nothing, no next event
                assert one.call("enterStepMode")[0] == 0
            seen, time = [], 0.0
            for values in inputs:
                for name, value in values.items():
                    one.set(name, value)
                status, event, terminate, early, last = one.do_step(time, 1e-3)
                assert (status, event, terminate, early) == (0, False, False, False)
                time = last
                seen.append(one.values())
            runs.append(seen)
        finally:
            one.close()
    assert runs[0] == runs[1]


def _period_means(samples, frequency, periods):
    """Mean power [W] of each period from (start, end, P_in) samples held over each step."""
    means = []
    for j in range(periods):
        a, b = j / frequency, (j + 1) / frequency
        means.append(sum(p * max(0.0, min(e, b) - max(s, a)) for s, e, p in samples) * frequency)
    return means


def test_the_pwm_driver_returns_early_at_its_edges(native_fmus, fmi3_fmus):
    """130 Hz (a period is no whole number of 1 ms steps), duty 0.3 of 2 W. With event mode
    and early return, a step stops at each edge, P_in is 2 W or 0 W (to rounding), and the
    mean power per period, from the outputs held over each step as a master sees them, is
    the exact duty-cycle value 0.6 W to 1e-9; the fixed-step FMI 2.0 run's per-period means are off by
    up to a step's share. Both errors are printed (pytest -s)."""
    frequency, periods, setup = 130.0, 12, {"frequency_Hz": 130.0, "peak_W": 2.0}
    runs = {}
    for version in ("v2", "v3"):
        one = (Instance(native_fmus["SmaPwmDriver"], "edges2") if version == "v2" else
               Instance3(fmi3_fmus["SmaPwmDriver"], "edges3", event_mode=True, early_return=True))
        try:
            assert one.start(dict(setup, P_demand=0.6)) == 0
            if version == "v3":
                assert one.call("enterStepMode")[0] == 0
            samples, time, events = [], 0.0, 0
            while time < periods / frequency - 1e-12:
                if version == "v3":
                    status, event, terminate, early, last = one.do_step(time, 1e-3)
                    assert status == 0 and not terminate and (early <= event)
                    if event:
                        events += 1
                        assert one.call("enterEventMode")[0] == 0
                        assert one.fmu.updateDiscreteStates()[0] is False
                        assert one.call("enterStepMode")[0] == 0
                else:
                    assert one.step(time, 1e-3) == 0
                    last = time + 1e-3
                samples.append((time, last, one.get("P_in")[1]))
                time = last
            runs[version] = samples
        finally:
            one.close()
    assert events >= 2 * periods - 1
    # rounding of the edge times leaves slivers of 1e-15 W around the edges
    assert all(min(abs(p), abs(p - 2.0)) < 1e-12 for _, _, p in runs["v3"])
    errors = {v: max(abs(m - 0.6) for m in _period_means(s, frequency, periods))
              for v, s in runs.items()}
    print(f"PWM 130 Hz, duty 0.3 of 2 W: largest error of the mean power per period: "
          f"FMI 2.0 fixed 1 ms steps {errors['v2']:.3g} W, FMI 3.0 event mode {errors['v3']:.3g} W")
    assert errors["v3"] < 1e-9 and errors["v2"] > 1000 * errors["v3"]


def test_the_signals_return_early_at_their_steps(fmi3_fmus):
    """Load switching at 5.7 ms and 21.3 ms, the reference stepping at 12.5 ms: with early
    return, steps of 1 ms end at each of these times, where the output has switched."""
    import json
    one = Instance3(fmi3_fmus["SmaScenarioSignals"], "signals3", event_mode=True,
                    early_return=True)
    try:
        reference = {"kind": "step", "initial_ohm": 45.0, "final_ohm": 40.0, "time_s": 0.0125}
        load = {"times_s": [0.0, 0.0057, 0.0213], "values_kg": [0.1, 0.2, 0.05]}
        assert one.start({"reference": json.dumps(reference), "load_profile": json.dumps(load)}) == 0
        assert one.fmu.updateDiscreteStates()[4:] == (True, 0.0057)
        assert one.call("enterStepMode")[0] == 0
        time, ends = 0.0, {}
        while time < 0.03 - 1e-12:
            status, event, terminate, early, last = one.do_step(time, 1e-3)
            assert status == 0 and not terminate
            if event:
                ends[round(last, 12)] = one.values()
                assert one.call("enterEventMode")[0] == 0
                assert one.call("enterStepMode")[0] == 0
            time = last
        assert set(ends) == {0.0057, 0.0125, 0.0213}
        assert ends[0.0057] == {"R_ref": 45.0, "load": 0.2}
        assert ends[0.0125]["R_ref"] == 40.0 and ends[0.0213]["load"] == 0.05
    finally:
        one.close()


def _assert_same_runs(one, other):
    """Two fmpy results equal column by column (the plant's reversal arrays, recorded as
    memory_depth columns, hold NaN past the live entries: NaN equals NaN here)."""
    assert one.dtype.names == other.dtype.names
    for column in one.dtype.names:
        assert np.array_equal(one[column], other[column], equal_nan=True), column


def test_fmpy_simulates_each(fmi3_fmus):
    from fmpy import simulate_fmu
    for name in NAMES:
        plain = simulate_fmu(str(fmi3_fmus[name]), stop_time=0.2, output_interval=1e-3)
        assert len(plain) >= 200 and plain["time"][-1] == pytest.approx(0.2)
        events = simulate_fmu(str(fmi3_fmus[name]), stop_time=0.2, output_interval=1e-3,
                              use_event_mode=True, early_return_allowed=True)
        if name != "SmaPwmDriver":  # no events before 0.2 s: the same run (the plant's
            # reversal arrays recorded too, NaN past the live entries)
            _assert_same_runs(events, plain)
        if name == "SmaActuator":  # the arrays: memory_depth (its start, 64) values a row
            assert plain["reversal_T"].shape == (len(plain), 64)


def test_fmi3_needs_the_c_family(capsys, tmp_path):
    assert main(["build", "--fmi", "3", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["sma-fmu: error: FMI 3.0 FMUs are built by the C family only (--native): "
                   "pythonfmu is FMI 2.0 only"]


def test_fmpy_compiles_one_from_its_build_description_alone(fmi3_fmus, tmp_path):
    """build_platform_binary (CMake over sources/buildDescription.xml): the same results."""
    import shutil
    from fmpy import simulate_fmu
    from fmpy.build import build_platform_binary
    folder = tmp_path / "unzipped"
    with zipfile.ZipFile(fmi3_fmus["SmaActuator"]) as archive:
        archive.extractall(folder)
    shutil.rmtree(folder / "binaries")
    build_platform_binary(folder.absolute())
    assert (folder / "binaries" / "x86_64-linux" / "SmaActuator.so").is_file()
    inputs = {"P_in": 1.2, "load": 0.15}
    compiled = simulate_fmu(str(folder), stop_time=2.0, step_size=1e-3, start_values=inputs)
    shipped = simulate_fmu(str(fmi3_fmus["SmaActuator"]), stop_time=2.0, step_size=1e-3,
                           start_values=inputs)
    _assert_same_runs(compiled, shipped)
    assert compiled["T"][-1] > compiled["T"][0]


@pytest.mark.parametrize("kind", [["ssp", "paper"], ["container", "setpoints-pwm-pi+ff-adaptive"],
                                  ["cross-check"]])
def test_export_refuses_fmi3_fmus_by_name(fmi3_fmus, capsys, tmp_path, kind):
    folder = fmi3_fmus["SmaActuator"].parent
    out = tmp_path / ("out.fmu" if kind[0] == "container" else "out")
    assert main(["export", *kind, "--fmus", str(folder), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"sma-fmu: error: export {kind[0]}: ")
    assert "is an FMI 3.0 FMU" in err[0] and not out.exists()


def test_corrupted_states_are_refused_alike_in_both_versions(native_fmus, fmi3_fmus):
    """The saved-state fuzz cases through both fronts: each corruption of a serialized state
    (a flipped byte, a cut, an extension, the other model's state) is refused with an error
    naming the function, never a crash, and both versions refuse the same cases."""
    rng = random.Random(38)
    twins = Versions(native_fmus, fmi3_fmus, "SmaFeedforward", "fuzz3")
    other = Instance3(fmi3_fmus["SmaPiController"], "fuzz3-other")
    try:
        assert twins.both("start", {"R_ref": 45.0, "load": 0.1}) == [0, 0]
        assert other.start() == 0
        twins.walk([{"R_ref": 44.0 + k * 1e-3} for k in range(200)])
        blobs = (twins.v2.fmu.serializeFMUstate(twins.v2.fmu.getFMUstate()),
                 twins.v3.fmu.serializeFMUState(twins.v3.fmu.getFMUState()))
        assert len(blobs[0]) == len(blobs[1])
        cases = []
        for _ in range(400):
            at = rng.randrange(len(blobs[0]))
            cases.append(("flip", at, rng.randrange(1, 256)))
        cases += [("cut", rng.randrange(len(blobs[0])), 0) for _ in range(50)]
        cases += [("extend", 0, rng.randrange(1, 256)) for _ in range(10)]
        for kind, at, value in cases:
            bad = []
            for blob in blobs:
                data = bytearray(blob)
                if kind == "flip":
                    data[at] ^= value
                elif kind == "cut":
                    del data[at:]
                else:
                    data.append(value)
                bad.append(bytes(data))
            v2 = twins.v2.call("deSerializeFMUstate", bad[0])[0]
            v3 = twins.v3.call("deserializeFMUState", bad[1])[0]
            assert v2 == v3 == 3, (kind, at, value, twins.v3.log[-1:])
            assert "fmi3DeserializeFMUState" in twins.v3.log[-1][1]
        foreign = other.fmu.serializeFMUState(other.fmu.getFMUState())
        assert twins.v3.call("deserializeFMUState", foreign)[0] == 3
        assert "SmaPiController" in twins.v3.log[-1][1]
        twins.walk([{"R_ref": 44.5}] * 10, time=0.2)  # both still step alike
    finally:
        twins.close()
        other.close()


def test_sma_fmu_check_passes_each(fmi3_fmus, capsys):
    """fmpy validation, FMI checker, state round trip (FMU3Slave), reference result,
    platforms from extra/org.sma-fmu.platforms/platforms.xml; libcosim's run is n/a (it runs
    no FMI 3.0)."""
    assert main(["check", *(str(fmi3_fmus[name]) for name in NAMES)]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert not [line for line in lines if line.startswith("FAIL")]
    for check in ("state round trip: FMI 3.0, serialized", "platform x86_64-linux: ",
                  "platform x86_64-windows: ", "C host (libcosim): libcosim runs no FMI 3.0",
                  "wire: sha256:"):
        assert sum(check in line for line in lines) == len(NAMES), check


def test_platforms_are_listed_outside_the_model_description(fmi3_fmus, tmp_path):
    """No top-level <Annotations> (the FMI Library 3.0.4 refuses one, docs/systems.md): the
    platforms file names every binary; a listed platform without its binary is a FAIL."""
    import xml.etree.ElementTree as ET
    import zipfile

    from sma_fmu.fmi.packaging.platforms import PLATFORMS_FILE, platform_report

    for name in NAMES:
        with zipfile.ZipFile(fmi3_fmus[name]) as archive:
            root = ET.fromstring(archive.read("modelDescription.xml"))
            listed = {node.get("binary") for node in
                      ET.fromstring(archive.read(PLATFORMS_FILE)).iterfind("Platform")}
            binaries = {n for n in archive.namelist() if n.startswith("binaries/")}
        assert root.find("Annotations") is None
        assert listed == binaries, name
    source = fmi3_fmus["SmaPwmDriver"]
    broken = tmp_path / "SmaPwmDriver.fmu"
    with zipfile.ZipFile(source) as old, zipfile.ZipFile(broken, "w") as new:
        for item in old.infolist():
            if item.filename != "binaries/x86_64-windows/SmaPwmDriver.dll":
                new.writestr(item, old.read(item.filename))
    assert ("FAIL", "x86_64-windows", f"declared in {PLATFORMS_FILE} but not in binaries/") \
        in platform_report(broken)
