"""The native (C) FMUs of ``sma-fmu build --native``: what they hold, and real hosts running them.

fmpy validates them and runs them (simulate_fmu), and compiles one from its sources/ alone
(build_platform_binary, CMake); the binaries link no libpython and export only the fmi2
functions; the interface is the pythonfmu twin's; packed start values are read; a host
without callbacks or with a '%' in the instance name crashes nothing; saved-state bytes
that are not one are refused with a message; a build without mingw-w64 warns and leaves
win64 out. (Equality with the pythonfmu FMUs: tests/native/test_native_equivalence.py.)
"""
import ctypes
import json
import math
import shutil
import subprocess
import sys
import warnings
import zipfile
from pathlib import Path

import pytest
from fmpy import extract, read_model_description, simulate_fmu

from native_twins import Instance
from sma_fmu.fmi.packaging.fmu_names import FMU_SCRIPTS
from sma_fmu.fmi.packaging.build import validate_fmus

pytestmark = pytest.mark.needs("gcc")


@pytest.fixture(scope="module")
def native(tmp_path_factory):
    """The five native FMUs, built by the command line: {name: path}."""
    out = tmp_path_factory.mktemp("native")
    result = subprocess.run([sys.executable, "-m", "sma_fmu", "build", "--native", "--out", str(out)],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert sorted(line.split(":")[0] for line in result.stdout.splitlines()) == sorted(FMU_SCRIPTS)
    return {name: out / f"{name}.fmu" for name in FMU_SCRIPTS}


@pytest.fixture(scope="module")
def twins(tmp_path_factory):
    from sma_fmu.fmi.packaging.build import build_fmus
    return build_fmus(tmp_path_factory.mktemp("python"))


def test_fmpy_validates_them(native):
    assert validate_fmus(native.values()) == {path: [] for path in native.values()}


@pytest.mark.parametrize("name", sorted(FMU_SCRIPTS))
def test_fmpy_simulates_each(native, name):
    result = simulate_fmu(str(native[name]), stop_time=0.5, step_size=1e-3)
    assert len(result) == 501
    for field in result.dtype.names:
        assert all(math.isfinite(float(v)) for v in result[field])


def test_interface_is_the_twins(native, twins):
    """Same variables, value references, types, causalities, variabilities, units,
    descriptions and start values (Reals: exact here, 15 digits in pythonfmu's XML)."""
    for name in FMU_SCRIPTS:
        ours = read_model_description(str(native[name]))
        theirs = read_model_description(str(twins[name]))
        assert ours.modelName == theirs.modelName
        assert not ours.coSimulation.needsExecutionTool and theirs.coSimulation.needsExecutionTool
        assert ours.coSimulation.canGetAndSetFMUstate and ours.coSimulation.canSerializeFMUstate
        assert len(ours.modelVariables) == len(theirs.modelVariables)
        for a, b in zip(ours.modelVariables, theirs.modelVariables):
            assert (a.name, a.valueReference, a.type, a.causality, a.variability, a.unit,
                    a.description, a.initial) == \
                   (b.name, b.valueReference, b.type, b.causality, b.variability, b.unit,
                    b.description, b.initial)
            if a.type == "Real" and a.start is not None:   # NaN: a wire parameter not given
                assert float(a.start) == pytest.approx(float(b.start), rel=1e-14, nan_ok=True)
            else:
                assert a.start == b.start


def test_binaries_have_no_python_and_export_only_fmi2(native):
    with zipfile.ZipFile(native["SmaActuator"]) as archive:
        names = archive.namelist()
        linux = archive.read("binaries/linux64/SmaActuator.so")
        windows = archive.read("binaries/win64/SmaActuator.dll") \
            if "binaries/win64/SmaActuator.dll" in names else None
    assert b"libpython" not in linux and b"Py_Initialize" not in linux
    if windows is not None:
        assert b"python3" not in windows.lower() and b"Py_Initialize" not in windows
    folder = Path(extract(str(native["SmaActuator"])))
    try:
        library = folder / "binaries" / "linux64" / "SmaActuator.so"
        if shutil.which("nm"):
            defined = subprocess.run(["nm", "-D", "--defined-only", str(library)],
                                     capture_output=True, text=True, check=True).stdout.split()
            exported = [word for word in defined[2::3]]
            assert len(exported) == 34 and all(name.startswith("fmi2") for name in exported)
        if shutil.which("readelf"):
            needed = subprocess.run(["readelf", "-d", str(library)], capture_output=True,
                                    text=True, check=True).stdout
            assert "NEEDED" in needed and "python" not in needed
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def test_fmpy_compiles_one_from_its_sources_alone(native, tmp_path):
    """build_platform_binary (CMake over <SourceFiles>): the result runs as the shipped one."""
    from fmpy.build import build_platform_binary
    folder = tmp_path / "unzipped"
    with zipfile.ZipFile(native["SmaFeedforward"]) as archive:
        archive.extractall(folder)
    shutil.rmtree(folder / "binaries")
    build_platform_binary(folder.absolute())
    assert (folder / "binaries" / "linux64" / "SmaFeedforward.so").is_file()
    compiled = simulate_fmu(str(folder), stop_time=0.3, step_size=1e-3,
                            start_values={"R_ref": 44.0, "load": 0.1})
    shipped = simulate_fmu(str(native["SmaFeedforward"]), stop_time=0.3, step_size=1e-3,
                           start_values={"R_ref": 44.0, "load": 0.1})
    assert compiled.tolist() == shipped.tolist()


def _with_start_values(path, target, values):
    """A copy of the FMU ``path`` with resources/start_values.json holding ``values``."""
    with zipfile.ZipFile(path) as source, zipfile.ZipFile(target, "w") as copy:
        for item in source.infolist():
            copy.writestr(item, source.read(item.filename))
        copy.writestr("resources/start_values.json", json.dumps({"source": "test", "values": values}))
    return target


def test_packed_start_values_are_read(native, tmp_path):
    packed = _with_start_values(native["SmaPiController"], tmp_path / "pi.fmu", {"Kp": 0.7, "Ki": 0})
    fmu = Instance(packed, "packed")
    try:
        assert fmu.get("Kp") == (3, None)  # instantiated: no get yet
        assert fmu.start({"R": 40.0, "R_ref": 35.0}) == 0
        assert fmu.values(["Kp", "Ki", "P"]) == {"Kp": 0.7, "Ki": 0.0, "P": 0.7 * 5.0}
    finally:
        fmu.close()


def test_a_bad_packed_value_fails_instantiation_naming_it(native, tmp_path):
    packed = _with_start_values(native["SmaPiController"], tmp_path / "pi.fmu", {"Kp": "high"})
    from native_twins import LOGS
    with pytest.raises(Exception):
        Instance(packed, "badpacked")
    assert "start_values.json: Kp = 'high' is not a valid Real start value" in LOGS["badpacked"][-1][1]


def _library(path, tmp_path):
    folder = tmp_path / path.stem
    with zipfile.ZipFile(path) as archive:
        archive.extractall(folder)
    library = ctypes.CDLL(str(folder / "binaries" / "linux64" / f"{path.stem}.so"))
    guid = read_model_description(str(path)).guid.encode()
    return library, guid, (folder / "resources").as_uri().encode()


def test_no_callbacks_no_crash(native, tmp_path):
    """fmi2Instantiate with functions = NULL: the calls work, refusals return fmi2Error."""
    library, guid, uri = _library(native["SmaActuator"], tmp_path)
    library.fmi2Instantiate.restype = ctypes.c_void_p
    library.fmi2Instantiate.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p,
                                        ctypes.c_char_p, ctypes.c_void_p, ctypes.c_int, ctypes.c_int]
    component = library.fmi2Instantiate(b"bare%s%n", 1, guid, uri, None, 0, 1)
    assert component
    c = ctypes.c_void_p(component)
    library.fmi2DoStep.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_int]
    assert library.fmi2DoStep(c, 0.0, 1e-3, 1) == 3  # illegal before initialization
    assert library.fmi2EnterInitializationMode(c) == 0
    assert library.fmi2ExitInitializationMode(c) == 0
    assert library.fmi2DoStep(c, 0.0, 1e-3, 1) == 0
    assert library.fmi2DoStep(c, 5.0, 1e-3, 1) == 3  # does not follow
    library.fmi2FreeInstance(c)
    assert library.fmi2Instantiate(b"x", 1, b"not-the-guid", uri, None, 0, 1) is None
    assert library.fmi2Instantiate(None, 1, guid, uri, None, 0, 1) is None
    assert library.fmi2Instantiate(b"x", 1, guid, None, None, 0, 1) is None


def test_bad_state_bytes_are_refused_with_a_message(native):
    fmu = Instance(native["SmaActuator"], "bytes")
    other = Instance(native["SmaPiController"], "other")
    try:
        assert fmu.start({"load": 0.1}) == 0 and other.start() == 0
        for k in range(50):
            fmu.set("P_in", 1.0)
            assert fmu.step(k * 1e-3, 1e-3) == 0
        blob = fmu.fmu.serializeFMUstate(fmu.fmu.getFMUstate())
        cases = {
            blob[:-3]: "truncated",
            blob + b"\0": "extended",
            b"XX" + blob[2:]: "does not start with SMAF",
            blob[:20] + b"XX" + blob[22:]: "checksum does not match",
            other.fmu.serializeFMUstate(other.fmu.getFMUstate()): "model 'SmaPiController'",
        }
        for bad, words in cases.items():
            status, _ = fmu.call("deSerializeFMUstate", bad)
            assert status == 3
            assert words in fmu.log[-1][1] and "refused" in fmu.log[-1][1]
        saved = fmu.values()
        for k in range(50, 60):
            assert fmu.step(k * 1e-3, 1e-3) == 0
        assert fmu.values() != saved
        assert fmu.call("setFMUstate", fmu.fmu.deSerializeFMUstate(blob))[0] == 0
        assert fmu.values() == saved
        assert fmu.step(0.05, 1e-3) == 0  # its time came back too
    finally:
        fmu.close()
        other.close()


def test_build_without_mingw_and_zig_warns_and_leaves_win64_out(tmp_path, monkeypatch):
    from sma_fmu.fmi.packaging.c_family_build import NativeBuildWarning, build_native_fmus
    from sma_fmu.fmi.packaging.platforms import platform_report
    monkeypatch.setenv("SMA_FMU_WIN64_CC", "no-such-mingw-gcc")
    monkeypatch.setenv("SMA_FMU_ZIG_CC", "none")  # nor zig cc, which builds win64 and darwin64 too
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        paths = build_native_fmus(tmp_path / "fmus", names=["SmaPwmDriver"])
    assert any(isinstance(w.message, NativeBuildWarning) and "win64" in str(w.message) for w in caught)
    with zipfile.ZipFile(paths["SmaPwmDriver"]) as archive:
        assert not [n for n in archive.namelist() if n.startswith("binaries/win64")]
    assert [(status, platform) for status, platform, _ in platform_report(paths["SmaPwmDriver"])] == \
        [("ok", "linux64")]


def _walk_commands(model, rng):
    """fmi_host commands: initialize, then 3000 steps of a random input walk, reading outputs."""
    inputs = {"SmaActuator": (0, (0.0, 3.0), "2 3 4 5 6 7"), "SmaFeedforward": (0, (38.0, 48.0), "2 3"),
              "SmaPiController": (0, (30.0, 50.0), "3 4"), "SmaPwmDriver": (0, (0.0, 12.0), "1"),
              "SmaScenarioSignals": (None, None, "0 1")}
    vr, span, outputs = inputs[model]
    lines = ["instantiate 0 6131 ok ok 0", "setup 0 0 -", "enter 0", "exit 0"]
    time, value = 0.0, 0.0
    for k in range(3000):
        if vr is not None:
            if k % 97 == 0:
                value = rng.uniform(*span)
            lines.append(f"setreal 0 1 {vr} {value!r}")
        lines += [f"step 0 {time!r} 0.001", f"getreal 0 {len(outputs.split())} {outputs}"]
        time += 0.001
    return "\n".join(lines + ["free 0", "end", ""])


def _outputs(text):
    rows = [line.split()[2:] for line in text.splitlines() if line.startswith("= 0 ") and len(line.split()) > 2]
    return [[float(v) for v in row] for row in rows]


@pytest.mark.needs("wine64", "mingw-w64")
def test_win64_binaries_run_under_wine_as_linux64(native, tmp_path, fmi_host_exe):
    """The first run of the model on Windows: a Windows C host (mingw) loads each win64
    binary under wine64 and steps it; the outputs equal linux64's to 1e-12 (mingw's libm is
    not glibc's: the last bit may differ)."""
    import random
    from sma_fmu.fmi.hosts import compile_host
    from system_needs import wine_command
    environment = {k: v for k, v in __import__("os").environ.items() if k != "LD_PRELOAD"}
    environment.update(WINEPREFIX=str(tmp_path / "prefix"), WINEDEBUG="-all", DISPLAY="")
    subprocess.run([wine_command(), "wineboot", "--init"], env=environment, capture_output=True,
                   timeout=600, check=True)
    windows_host = compile_host("fmi_host", tmp_path / "hosts", windows=True)
    largest = {}
    for name, path in native.items():
        folder = tmp_path / name
        with zipfile.ZipFile(path) as archive:
            archive.extractall(folder)
        commands = _walk_commands(name, random.Random(name))
        linux = subprocess.run([str(fmi_host_exe), str(folder)], input=commands, text=True,
                               capture_output=True, timeout=600, check=True).stdout
        windows = subprocess.run([wine_command(), str(windows_host), "Z:" + str(folder).replace("/", "\\")],
                                 input=commands, text=True, capture_output=True, timeout=600,
                                 env=environment, check=True).stdout
        a, b = _outputs(linux), _outputs(windows)
        assert len(a) == len(b) == 3000
        largest[name] = max(abs(x - y) / max(abs(x), abs(y), 1e-300)
                            for row_a, row_b in zip(a, b) for x, y in zip(row_a, row_b))
    print("win64 under wine against linux64, largest relative difference:", largest)
    assert all(value <= 1e-12 for value in largest.values())


def test_sma_fmu_check_passes_a_native_fmu(native):
    """sma-fmu check: fmpy, the FMI checker, libcosim, the state round trip, the reference
    result and each platform, declared native and without Python."""
    result = subprocess.run([sys.executable, "-m", "sma_fmu", "check", str(native["SmaPiController"])],
                            capture_output=True, text=True)
    lines = result.stdout.splitlines()
    assert result.returncode == 0 and not [line for line in lines if line.startswith("FAIL")], result.stdout
    platforms = [line for line in lines if "platform" in line]
    assert platforms and all(line.startswith("ok") and "native C" in line and "no Python" in line
                             for line in platforms)


def test_resource_locations_taken_and_refused_as_the_front_does(native, tmp_path):
    """file:///abs, file:/abs, file://localhost/abs, percent escapes and a plain absolute path
    are taken; another host, a relative path, another scheme, a missing folder are refused
    (NULL, never a crash)."""
    library, guid, uri = _library(native["SmaPiController"], tmp_path)
    library.fmi2Instantiate.restype = ctypes.c_void_p
    library.fmi2Instantiate.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p,
                                        ctypes.c_char_p, ctypes.c_void_p, ctypes.c_int, ctypes.c_int]
    library.fmi2FreeInstance.argtypes = [ctypes.c_void_p]
    folder = str(tmp_path / "SmaPiController" / "resources")
    spaced = tmp_path / "with space" / "resources"  # the FMU's resources, in a spaced path
    spaced.mkdir(parents=True)
    for name in ("parameters.json", "model_starts.json"):
        (spaced / name).write_bytes((Path(folder) / name).read_bytes())
    taken = [uri, f"file:{folder}", f"file://localhost{folder}", folder,
             "file://" + str(spaced).replace(" ", "%20")]
    refused = ["http://example.com/resources", "file://elsewhere" + folder, "file:resources",
               f"file://{folder}/missing", "file://" + folder + "%zz", "",
               (tmp_path / "with space").as_uri()]  # exists, but holds no parameters.json
    for text in taken:
        component = library.fmi2Instantiate(b"u", 1, guid, text if isinstance(text, bytes) else text.encode(),
                                            None, 0, 0)
        assert component, text
        library.fmi2FreeInstance(component)
    for text in refused:
        assert library.fmi2Instantiate(b"u", 1, guid, text.encode(), None, 0, 0) is None, text
