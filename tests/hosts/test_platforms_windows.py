"""win64: the Windows front, cross-built with mingw-w64, checked without Windows.

What can be checked here, and is:
- the DLL exports every FMI 2.0 co-simulation function (the same set as the Linux front)
  and imports only what every Windows has (KERNEL32, ADVAPI32, msvcrt);
- under Debian's wine64, with a Windows build of the plain C host (fmi_host.exe): resource
  URIs and the GUID are checked the Windows way (file:///Z:/...); with no Windows Python,
  fmi2Instantiate returns NULL with one message naming what was tried and
  SMA_FMU_LIBPYTHON, and the host goes on (no crash); a Python found in the registry
  (PEP 514) is loaded; an old one is refused, naming its version.
The "Pythons" are fakes: a few lines of C reporting a version. Running the FMU through a
real Windows Python was not done here (docs/fmus.md, "Platforms"). Needs gcc,
gcc-mingw-w64-x86-64 and, under wine, wine64: skipped without them, failed under CI=true
(.ci/run installs them; tests/support/system_needs.py).
"""
import struct
import subprocess
from pathlib import Path

import pytest

from fmi_host import ERROR, FmiHost, text
from sma_fmu.fmi.hosts import compile_host, windows_compiler
from sma_fmu.fmi.packaging.platforms import FRONT_MARKER
from system_needs import need, needs, wine_command

pytestmark = needs("gcc", "mingw-w64")  # the session's FMUs carry the win64 front
WINE = wine_command()
FMI2_CO_SIMULATION = {
    "fmi2GetTypesPlatform", "fmi2GetVersion", "fmi2SetDebugLogging", "fmi2Instantiate",
    "fmi2FreeInstance", "fmi2SetupExperiment", "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode", "fmi2Terminate", "fmi2Reset", "fmi2GetReal", "fmi2GetInteger",
    "fmi2GetBoolean", "fmi2GetString", "fmi2SetReal", "fmi2SetInteger", "fmi2SetBoolean",
    "fmi2SetString", "fmi2GetFMUstate", "fmi2SetFMUstate", "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize", "fmi2SerializeFMUstate", "fmi2DeSerializeFMUstate",
    "fmi2GetDirectionalDerivative", "fmi2SetRealInputDerivatives", "fmi2GetRealOutputDerivatives",
    "fmi2DoStep", "fmi2CancelStep", "fmi2GetStatus", "fmi2GetRealStatus", "fmi2GetIntegerStatus",
    "fmi2GetBooleanStatus", "fmi2GetStringStatus"}
FAKE_PYTHON = """
__declspec(dllexport) const char* Py_GetVersion(void) { return VERSION " (a fake of the tests)"; }
__declspec(dllexport) int Py_IsInitialized(void) { return 0; }
"""


def _pe_sections(data):
    offset = struct.unpack_from("<I", data, 0x3C)[0]
    assert data[offset:offset + 4] == b"PE\0\0"
    count, optional_size = struct.unpack_from("<H", data, offset + 6)[0], \
        struct.unpack_from("<H", data, offset + 20)[0]
    optional = offset + 24
    assert struct.unpack_from("<H", data, optional)[0] == 0x20B  # PE32+: 64-bit
    directories = optional + 112
    table = optional + optional_size
    sections = [struct.unpack_from("<8sIIII", data, table + 40 * i) for i in range(count)]

    def at(rva):
        for _, size, address, raw_size, raw in sections:
            if address <= rva < address + max(size, raw_size):
                return rva - address + raw
        raise ValueError(f"RVA {rva:#x} in no section")

    return directories, at


def pe_exports(data):
    """The names a PE DLL exports."""
    directories, at = _pe_sections(data)
    rva = struct.unpack_from("<I", data, directories)[0]
    count, names = struct.unpack_from("<I", data, at(rva) + 24)[0], struct.unpack_from("<I", data, at(rva) + 32)[0]
    result = set()
    for i in range(count):
        start = at(struct.unpack_from("<I", data, at(names) + 4 * i)[0])
        result.add(data[start:data.index(b"\0", start)].decode())
    return result


def pe_imports(data):
    """The DLLs a PE binary imports."""
    directories, at = _pe_sections(data)
    rva = struct.unpack_from("<I", data, directories + 8)[0]
    result, entry = set(), at(rva)
    while True:
        name = struct.unpack_from("<I", data, entry + 12)[0]
        if name == 0:
            return result
        start = at(name)
        result.add(data[start:data.index(b"\0", start)].decode().upper())
        entry += 20


@pytest.fixture(scope="module")
def windows_dll(plant_folder):
    need("mingw-w64")
    dll = plant_folder / "binaries/win64/SmaActuator.dll"
    assert dll.is_file(), f"no win64 front, although {windows_compiler()[0]} is there"
    return dll.read_bytes()


def test_the_dll_is_the_front_and_exports_every_fmi2_function(windows_dll, plant_folder):
    assert FRONT_MARKER in windows_dll
    exports = pe_exports(windows_dll)
    assert exports == FMI2_CO_SIMULATION | {"sma_fmu_front", "sma_fmu_front_share", "sma_fmu_step"}
    linux = subprocess.run(["nm", "-D", "--defined-only", str(plant_folder / "binaries/linux64/SmaActuator.so")],
                           capture_output=True, text=True, check=True).stdout
    assert {line.split()[-1] for line in linux.splitlines()} == exports


def test_the_dll_needs_only_what_every_windows_has(windows_dll, plant_folder):
    assert pe_imports(windows_dll) <= {"KERNEL32.DLL", "ADVAPI32.DLL", "MSVCRT.DLL"}
    backend = (plant_folder / "binaries/win64/SmaActuator_pythonfmu.dll").read_bytes()
    assert "PYTHON3.DLL" in pe_imports(backend)  # pythonfmu's: the stable ABI of any Python 3


@pytest.fixture(scope="module")
def wine(wine, tmp_path_factory):
    """(environment, host runner): the module's wine64 prefix (the conftest's ``wine``) and a
    script running the Windows build of the plain C host under it."""
    need("mingw-w64")
    root = tmp_path_factory.mktemp("wine_host")
    exe = compile_host("fmi_host", root / "hosts", windows=True)
    runner = root / "fmi_host_under_wine"
    runner.write_text(f'#!/bin/sh\nexec "{WINE}" "{exe}" "$1"\n')
    runner.chmod(0o755)
    return wine, runner


def _windows(path):
    return "Z:" + str(Path(path).resolve()).replace("/", "\\")


def _fake_python(folder, name, version):
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "fake.c").write_text(FAKE_PYTHON)
    subprocess.run([*windows_compiler(), "-shared", "-O2", f'-DVERSION="{version}"', "-o",
                    str(folder / name), str(folder / "fake.c")], check=True, capture_output=True)
    return folder / name


def _finish(host):
    host.process.stdin.write("end\n")
    host.process.stdin.close()
    code = host.process.wait(timeout=120)
    return code, host.process.stdout.read()


@needs("wine64")
def test_without_a_windows_python_instantiate_gives_null_and_says_what_to_do(wine, plant_folder):
    environment, runner = wine
    host = FmiHost(runner, _windows(plant_folder), env=environment)
    reply = host.call(f"instantiate 0 {text('plant')} ok ok 0")
    again = host.call(f"instantiate 1 {text('plant')} ok ok 0")
    code, rest = _finish(host)
    assert reply.status == ERROR and again.status == ERROR
    assert code == 0 and "bye" in rest  # no crash: the host ended normally
    errors = reply.logged(ERROR)
    assert len(errors) == 1 and "\n" not in errors[0]
    for part in ("needs a Python 3.10 or newer for Windows", "SMA_FMU_LIBPYTHON: not set",
                 "Software\\Python\\PythonCore\\3.X\\InstallPath", "python3X.dll on the DLL search path",
                 "set SMA_FMU_LIBPYTHON to the full path of its python3X.dll"):
        assert part in errors[0], (part, errors[0])


@pytest.mark.parametrize("uri, guid, message", [
    ("missing", "ok", "does not exist"), ("http", "ok", "is not a file: URI"),
    ("relative", "ok", "is not an absolute path"), ("ok", "wrong", "does not match the guid")])
@needs("wine64")
def test_resource_uris_and_guid_are_checked_the_windows_way(wine, plant_folder, uri, guid, message):
    environment, runner = wine
    host = FmiHost(runner, _windows(plant_folder), env=environment)
    reply = host.call(f"instantiate 0 {text('plant')} {uri} {guid} 0")
    code, _ = _finish(host)
    assert reply.status == ERROR and code == 0
    assert any(message in m for m in reply.logged(ERROR)), reply.logs


@needs("wine64")
def test_a_python_of_the_registry_is_found_and_an_old_one_refused(wine, plant_folder, tmp_path):
    environment, runner = wine
    newest = _fake_python(tmp_path / "Python312", "python312.dll", "3.12.0")
    subprocess.run([WINE, "reg", "add", r"HKCU\Software\Python\PythonCore\3.12\InstallPath", "/ve",
                    "/d", _windows(newest.parent), "/f"], env=environment, capture_output=True,
                   check=True, timeout=120)
    try:
        host = FmiHost(runner, _windows(plant_folder), env=environment)
        found = host.call(f"instantiate 0 {text('plant')} ok ok 0")
        code, _ = _finish(host)
    finally:
        subprocess.run([WINE, "reg", "delete", r"HKCU\Software\Python\PythonCore\3.12", "/f"],
                       env=environment, capture_output=True, timeout=120)
    assert found.status == ERROR and code == 0
    # the fake has no GIL API: the front says which Python it took
    assert any(f"lacks the GIL API (loaded {_windows(newest)} (Python 3.12.0))" in m
               for m in found.logged(ERROR)), found.logs
    old = _fake_python(tmp_path / "Python36", "python36.dll", "3.6.9")
    host = FmiHost(runner, _windows(plant_folder), env={**environment, "SMA_FMU_LIBPYTHON": _windows(old)})
    refused = host.call(f"instantiate 0 {text('plant')} ok ok 0")
    code, _ = _finish(host)
    assert refused.status == ERROR and code == 0
    assert any("Python 3.6.9 is not supported: this FMU needs Python 3.10 or newer" in m
               for m in refused.logged(ERROR)), refused.logs
