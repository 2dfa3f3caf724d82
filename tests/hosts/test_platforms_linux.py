"""linux64: the front finds a Python 3.10 or newer wherever the FMU is run, and says so.

The FMU records the libpython of the Python that built it. A C host on another machine
has another one, or none. The tests make that machine out of this one:
- a child process in a mount namespace in which the build's libpython folder is an empty
  folder (``unshare --mount``, as root): the FMU runs through the system's libpython
  (Debian's libpython3.11, which .ci/run installs);
- a front recording a Python that is installed nowhere (3.99): it takes the newest
  libpython of the standard places;
- a chroot holding only the host, the FMU and the C libraries they link: no Python at
  all. fmi2Instantiate returns NULL with one logged line naming what was tried and
  SMA_FMU_LIBPYTHON;
- fake libpythons (a few lines of C reporting a version) for the newest-first order and
  for refused versions (issue 21: Python 3.6 and 2.7 used to fail with a SyntaxError or an
  undefined symbol).
Needs root (unshare, chroot), gcc, and Debian's libpython3.11: skipped without them, failed
under CI=true (.ci/run installs them; tests/support/system_needs.py).
"""
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from fmi_host import ERROR, OK, FmiHost, text, unpack
from sma_fmu.fmi.packaging.front_build import compile_front, libpython_path
from sma_fmu.fmi.hosts import c_compiler
from sma_fmu.runtime.plant import PlantStepper
from system_needs import needs

pytestmark = needs("gcc")  # the C host, the front and the fake libpythons

SYSTEM_LIBPYTHON = Path("/usr/lib/x86_64-linux-gnu/libpython3.11.so.1.0")
STANDARD_FOLDERS = ("/usr/local/lib", "/usr/local/lib64", "/usr/lib/x86_64-linux-gnu",
                    "/lib/x86_64-linux-gnu", "/usr/lib64", "/lib64", "/usr/lib", "/lib")
FAKE_LIBPYTHON = """
const char* Py_GetVersion(void) { return VERSION " (a fake libpython of the tests)"; }
int Py_IsInitialized(void) { return 0; }
"""


def _run_plant(host, steps=20):
    """Instantiate, initialize and step the plant; returns (instantiate reply, [R, T])."""
    reply = host.call(f"instantiate 0 {text('plant')} ok ok 1")
    assert reply.status == OK, reply.logs
    for line in ("setup 0 0 -", "enter 0", "exit 0", "setreal 0 2 0 2.0 1 0.05"):
        assert host.call(line).status == OK
    for k in range(steps):
        assert host.call(f"step 0 {k * 0.01!r} 0.01").status == OK
    return reply, [float(v) for v in host.call("getreal 0 2 2 3").values]


def _library_plant(params, steps=20):
    stepper = PlantStepper(params, load=0.05)
    for _ in range(steps):
        out = stepper.step(2.0, 0.05, 0.01)
    return [out.R, out.T]


def _loaded(reply):
    """(path, version) from the front's "loaded libpython PATH (Python X.Y.Z)" line."""
    for _, _, message in reply.logs:
        match = re.search(r"loaded libpython (\S+) \(Python (\S+)\)", message)
        if match:
            return match.group(1), match.group(2)
    raise AssertionError(f"no 'loaded libpython' line in {reply.logs}")


def _script(path, body):
    path.write_text("#!/bin/sh\n" + body)
    path.chmod(0o755)
    return path


def _fake_libpython(folder, name, version):
    folder.mkdir(parents=True, exist_ok=True)
    source = folder / "fake.c"
    source.write_text(FAKE_LIBPYTHON)
    subprocess.run([*c_compiler(), "-shared", "-fPIC", f'-DVERSION="{version}"', "-o", str(folder / name),
                    str(source)], check=True, capture_output=True)
    return folder / name


@needs("root", "libpython3.11")
def test_the_build_libpython_hidden_the_fmu_runs_through_the_systems(fmi_host_exe, plant_folder,
                                                                      params, tmp_path):
    build_libpython = libpython_path()[0]
    assert build_libpython, "the tests' Python must be a shared build (it is what built the FMU)"
    assert SYSTEM_LIBPYTHON.is_file(), "Debian's libpython3.11 is needed (.ci/run installs it)"
    hidden = Path(build_libpython).parent
    assert not SYSTEM_LIBPYTHON.resolve().is_relative_to(hidden.resolve())
    (tmp_path / "empty").mkdir()
    host = _script(tmp_path / "host-without-the-builds-libpython",
                   f"exec unshare --mount --propagation private sh -c 'mount --bind \"$1\" \"$2\" && "
                   f"test ! -e \"$3\" && shift 3 && exec \"$@\"' sh {tmp_path / 'empty'} {hidden} "
                   f"{build_libpython} {fmi_host_exe} \"$1\"\n")
    with FmiHost(host, plant_folder) as fmi:
        reply, values = _run_plant(fmi)
        assert fmi.close() == 0
    path, version = _loaded(reply)
    assert Path(path).resolve() == SYSTEM_LIBPYTHON.resolve() and version.startswith("3.11.")
    assert values == pytest.approx(_library_plant(params), abs=1e-9)


def _front_built_elsewhere(fmus, folder):
    """The plant unpacked into ``folder`` with a front that records a Python 3.99."""
    front = compile_front(libpython=("/nonexistent/lib/libpython3.99.so.1.0", "libpython3.99.so.1.0"))
    assert front.library is not None, front.problem
    unpack(fmus["SmaActuator"], folder)
    (folder / "binaries/linux64/SmaActuator.so").write_bytes(front.library)
    return folder


@needs("system-libpython")
def test_a_python_not_installed_here_is_replaced_by_the_newest_installed(fmi_host_exe, fmus, params,
                                                                         tmp_path):
    folder = _front_built_elsewhere(fmus, tmp_path / "plant")
    installed = {}
    for standard in STANDARD_FOLDERS:
        for found in Path(standard).glob("libpython3.*.so.1.0"):
            minor = int(found.name.split(".")[1])
            if minor >= 10:
                installed.setdefault(minor, found)
    assert installed, "Debian's libpython3.11 is needed (.ci/run installs it)"
    with FmiHost(fmi_host_exe, folder) as fmi:
        reply, values = _run_plant(fmi)
    path, version = _loaded(reply)
    assert version.startswith(f"3.{max(installed)}.")
    assert Path(path).resolve() == installed[max(installed)].resolve()
    assert values == pytest.approx(_library_plant(params), abs=1e-9)


def test_newest_first_on_the_library_path(fmi_host_exe, fmus, tmp_path):
    folder = _front_built_elsewhere(fmus, tmp_path / "plant")
    fakes = tmp_path / "fakes"
    newest = _fake_libpython(fakes, "libpython3.38.so.1.0", "3.38.0")
    _fake_libpython(fakes, "libpython3.37.so.1.0", "3.37.1")
    environment = {k: v for k, v in os.environ.items() if k not in ("LD_PRELOAD", "SMA_FMU_LIBPYTHON")}
    environment["LD_LIBRARY_PATH"] = str(fakes)
    with FmiHost(fmi_host_exe, folder, env=environment) as fmi:
        reply = fmi.call(f"instantiate 0 {text('plant')} ok ok 1")
    assert reply.status == ERROR
    # the fake has no GIL API: the front says which Python it chose, the newest
    assert any(f"loaded libpython {newest} (Python 3.38.0)" in m and "lacks the GIL API" in m
               for m in reply.logged(ERROR)), reply.logs


def _minimal_root(root, fmi_host_exe, folder):
    """A chroot with the host, the FMU and the C libraries they link: no Python anywhere."""
    files = [Path(fmi_host_exe), folder / "binaries/linux64/SmaActuator.so",
             folder / "binaries/linux64/SmaActuator_pythonfmu.so"]
    libraries = set()
    for binary in files:
        listing = subprocess.run(["ldd", str(binary)], capture_output=True, text=True, check=True).stdout
        libraries |= set(re.findall(r"(/\S+) \(0x", listing))
    assert not any("libpython" in library for library in libraries)
    for library in libraries:
        target = root / library.lstrip("/")
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(library, target)  # follows the symlink: the file under its linked name
    shutil.copy2(fmi_host_exe, root / "fmi_host")
    shutil.copytree(folder, root / "fmu")
    return root


@needs("root")
def test_no_python_at_all_gives_null_and_one_line_naming_what_was_tried(fmi_host_exe, plant_folder,
                                                                        tmp_path):
    root = _minimal_root(tmp_path / "root", fmi_host_exe, plant_folder)
    host = _script(tmp_path / "host-in-chroot", f"exec chroot {root} /fmi_host /fmu\n")
    with FmiHost(host, "/fmu") as fmi:
        reply = fmi.call(f"instantiate 0 {text('plant')} ok ok 0")
        assert reply.status == ERROR
        assert fmi.call(f"instantiate 1 {text('again')} ok ok 0").status == ERROR  # no crash
        assert fmi.close() == 0
    errors = reply.logged(ERROR)
    assert len(errors) == 1 and "\n" not in errors[0]
    message = errors[0]
    for part in ("Python 3.10 or newer", "SMA_FMU_LIBPYTHON: not set", "SMA_FMU_LIBPYTHON to the full path",
                 f"the build's {libpython_path()[0]}: not found", f"{libpython_path()[1]}: not found",
                 "libpython3.40.so.1.0 to libpython3.10.so.1.0 through the library search path",
                 "/usr/lib/x86_64-linux-gnu", "/usr/local/lib"):
        assert part in message, (part, message)


@pytest.mark.parametrize("name, version", [("libpython3.6m.so.1.0", "3.6.15"),
                                           ("libpython2.7.so.1.0", "2.7.18"),
                                           ("libpython3.9.so.1.0", "3.9.18")])
def test_an_unsupported_python_is_refused_naming_its_version(fmi_host_exe, plant_folder, tmp_path,
                                                             name, version):
    fake = _fake_libpython(tmp_path, name, version)
    environment = {k: v for k, v in os.environ.items() if k != "LD_PRELOAD"}
    with FmiHost(fmi_host_exe, plant_folder, env={**environment, "SMA_FMU_LIBPYTHON": str(fake)}) as fmi:
        chosen = fmi.call(f"instantiate 0 {text('plant')} ok ok 0")
        assert fmi.close() == 0
    with FmiHost(fmi_host_exe, plant_folder, env={**environment, "LD_PRELOAD": str(fake)}) as fmi:
        in_process = fmi.call(f"instantiate 0 {text('plant')} ok ok 0")
        assert fmi.close() == 0
    assert chosen.status == ERROR and in_process.status == ERROR
    refusal = f"Python {version} is not supported: this FMU needs Python 3.10 or newer"
    assert any(f"SMA_FMU_LIBPYTHON={fake} cannot be used: {refusal}" in m for m in chosen.logged(ERROR))
    assert any(f"the Python in this process: {refusal}" in m for m in in_process.logged(ERROR))
