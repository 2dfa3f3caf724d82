"""The C front of the FMUs: compiled by the build, for Linux and Windows.

pythonfmu's binary needs libpython preloaded in C hosts, crashes on some resource URIs,
passes log messages to the host as printf formats and cannot report fmi2Error for a
refused call. The front (C sources in ``sma_fmu/fmi/python_family/front/``, shipped with the package)
fixes that: it becomes ``binaries/linux64/<model>.so`` and ``binaries/win64/<model>.dll``
and forwards every call to pythonfmu's binary, renamed ``<model>_pythonfmu.so`` /
``.dll`` (see ``front/fmi2_exports.c``).

- linux64: compiled with :func:`~sma_fmu.fmi.hosts.c_compiler` (``$CC``, default ``cc``).
  It records the shared libpython of the Python running the build, and finds another
  (3.10 or newer) where that one is absent. Where no compiler works the FMU keeps
  pythonfmu's plain binary, and its model description says what is degraded.
- win64: cross-compiled with mingw-w64 (``$SMA_FMU_WIN64_CC``, default
  ``x86_64-w64-mingw32-gcc``, :func:`~sma_fmu.fmi.hosts.windows_compiler`; Debian:
  ``apt-get install gcc-mingw-w64-x86-64``). Without
  it the FMU leaves win64 out.
Either case is a :class:`FrontWarning`; :mod:`sma_fmu.fmi.packaging.platforms` writes and
reads what each FMU says about its platforms.
"""
import hashlib
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import zipfile
from pathlib import Path

from sma_fmu.fmi.c_common import C_COMMON, FMI_HEADERS, include_flags
from sma_fmu.fmi.hosts import c_compiler, windows_compiler
from sma_fmu.fmi.packaging.prebuilt import find_prebuilt_front, sources_digest
from sma_fmu.console.interrupts import run_child
from sma_fmu.fmi.packaging.platforms import (DEGRADED, HOW_PYTHON_IS_FOUND, PLATFORMS, PlatformEntry,
                                   annotate, check_build_machine)

__all__ = ["FrontWarning", "FrontBuild", "Fronts", "compile_front", "compile_windows_front",
           "compile_fronts", "install_fronts", "remove_front", "libpython_path", "stage_slave_module"]

_BACKEND = "_pythonfmu"
_COMMON = ["-std=c11", "-O2", "-shared", "-Wall"]
_LINUX = {"flags": [*_COMMON, "-fPIC", "-fvisibility=hidden", "-Wl,--no-undefined"],
          "libraries": ["-ldl", "-lpthread"], "output": "front.so"}
_WINDOWS = {"flags": [*_COMMON, "-s", "-static-libgcc", "-D__USE_MINGW_ANSI_STDIO=1",
                       "-Wl,--no-insert-timestamp", "-Wl,--disable-auto-image-base"],
            "libraries": ["-ladvapi32"], "output": "front.dll"}
_compiled = {}  # (compiler, sources digest, defines) -> FrontBuild
FRONT = Path(__file__).parents[1] / "python_family" / "front"   # the front's C sources


class FrontWarning(UserWarning):
    """An FMU was built without the C front for a platform (no compiler for it)."""


class FrontBuild:
    """A compiled front (``library`` bytes) or the reason there is none (``problem``)."""

    def __init__(self, library=None, problem=None):
        self.library, self.problem = library, problem


class Fronts:
    """The front of each platform (:class:`FrontBuild` by platform name) and the libpython
    the linux64 one records."""

    def __init__(self, builds, libpython=("", "")):
        self.builds, self.libpython = dict(builds), libpython
        self.prebuilt = set()  # platforms whose front is the wheel's prebuilt one

    def warnings(self):
        """One message per platform that gets no front: what the FMUs lose there."""
        messages = []
        linux, windows = self.builds.get("linux64"), self.builds.get("win64")
        if linux is not None and linux.library is None:
            messages.append(
                f"FMUs built without the C front for linux64: {linux.problem}. They keep "
                "pythonfmu's own binary there, and their modelDescription.xml says what that "
                "degrades: C hosts need libpython in LD_PRELOAD, and refused calls are only "
                "logged, not returned as fmi2Error (docs/fmus.md, 'Without the C front')")
        if windows is not None and windows.library is None:
            messages.append(
                f"FMUs built without win64: {windows.problem}. Install mingw-w64 (Debian: "
                "apt-get install gcc-mingw-w64-x86-64) or set SMA_FMU_WIN64_CC to build the "
                "Windows front (docs/fmus.md, 'Platforms')")
        return messages


def libpython_path():
    """(absolute path or "", soname) of this Python's shared libpython, as sysconfig says."""
    soname = sysconfig.get_config_var("INSTSONAME") or ""
    if not (soname.startswith("libpython") and ".so" in soname):  # a static build
        soname = f"libpython{sys.version_info[0]}.{sys.version_info[1]}.so.1.0"
    path = Path(sysconfig.get_config_var("LIBDIR") or "/nonexistent") / soname
    return (str(path) if path.is_file() else ""), soname


def _source_files():
    """{file name: path} of what the front compiles: its own sources (``python_family/front/``),
    the C code both families share (``fmi/c_common/``) and the FMI standard's headers
    (``c_common/include/``, found through the include path)."""
    return {path.name: path for folder in (FRONT, C_COMMON, FMI_HEADERS)
            for path in sorted(folder.iterdir()) if path.suffix in (".c", ".h")}


def _sources():
    """{file name: bytes} of :func:`_source_files`: what the compiled front is a function of."""
    return {name: path.read_bytes() for name, path in _source_files().items()}


def _compile_cached(compiler, target, defines):
    sources = _sources()
    digest = hashlib.sha256(b"".join(name.encode() + data for name, data in sorted(sources.items())))
    key = (tuple(compiler), target["output"], digest.hexdigest(), tuple(defines))
    if key not in _compiled:
        _compiled[key] = _compile(compiler, target, defines)
    return _compiled[key]


def _compile(compiler, target, defines):
    """Compile the front's .c files where they are (in file-name order: the link order of
    every build), the headers found through :func:`~sma_fmu.fmi.c_common.include_flags`."""
    with tempfile.TemporaryDirectory(prefix="sma_fmu_front_") as folder:
        output = Path(folder) / target["output"]
        command = [*compiler, *target["flags"], *defines, *include_flags(FRONT, C_COMMON),
                   "-o", str(output),
                   *[str(path) for name, path in sorted(_source_files().items()) if name.endswith(".c")],
                   *target["libraries"]]
        try:
            result = run_child(command, text=True, timeout=300, own_temp=True)
        except (OSError, subprocess.SubprocessError) as error:
            return FrontBuild(problem=f"C compiler {' '.join(compiler)!r} could not run ({error})")
        if result.returncode != 0 or not output.is_file():
            last = (result.stderr.strip().splitlines() or ["no message"])[-1]
            return FrontBuild(problem=f"C compiler {' '.join(compiler)!r} failed: {last}")
        return FrontBuild(library=output.read_bytes())


def compile_front(libpython=None):
    """The linux64 front, compiled once per process and compiler: a :class:`FrontBuild`.

    ``libpython`` is the (path, soname) the front tries first when the host has no Python;
    default :func:`libpython_path` (the Python running the build).
    """
    if not (sys.platform.startswith("linux") and sys.maxsize > 2 ** 32):
        return FrontBuild(problem=f"the linux64 front is built on 64-bit Linux only (this is {sys.platform})")
    path, soname = libpython_path() if libpython is None else libpython
    return _compile_cached(c_compiler(), _LINUX, [f'-DSMA_FRONT_LIBPYTHON="{path}"',
                                                  f'-DSMA_FRONT_LIBPYTHON_SONAME="{soname}"'])


def compile_windows_front():
    """The win64 front, cross-compiled with :func:`windows_compiler`: a :class:`FrontBuild`."""
    compiler = windows_compiler()
    if shutil.which(compiler[0]) is None:
        return FrontBuild(problem=f"no mingw-w64 cross compiler ({compiler[0]} not found)")
    return _compile_cached(compiler, _WINDOWS, [])


def compile_fronts():
    """Check the build machine (:func:`~sma_fmu.fmi.packaging.platforms.check_build_machine`, which
    raises on one pythonfmu has no binary for), then compile the front of each platform."""
    check_build_machine()
    fronts = Fronts({"linux64": compile_front(), "win64": compile_windows_front()}, libpython_path())
    digest = sources_digest(_sources())
    for platform, build in fronts.builds.items():
        if build.library is None:  # no compiler for it here: the wheel's, of the same sources
            library = find_prebuilt_front(platform, digest)
            if library is not None:
                fronts.builds[platform] = FrontBuild(library=library)
                fronts.prebuilt.add(platform)
    return fronts


def _entry(platform, binary, front, libpython, prebuilt=False):
    python = HOW_PYTHON_IS_FOUND.get(platform, "")
    if platform == "linux64" and libpython[0]:
        python += f" (the build's: {libpython[0]})"
    if prebuilt:
        python += " (the installed package's prebuilt front: no build libpython recorded)"
    return PlatformEntry(platform, binary, front, python, "" if front else DEGRADED)


def install_fronts(fmu_path, model_identifier, fronts):
    """Put each platform's front into the FMU ``fmu_path``, before pythonfmu's binary (renamed
    ``<model>_pythonfmu.<suffix>``); leave win64 out where it has no front; keep pythonfmu's
    binary alone elsewhere. The model description then lists each platform (VendorAnnotations)."""
    fmu_path = Path(fmu_path)
    rewritten = fmu_path.with_suffix(".front.tmp")
    entries = []
    with zipfile.ZipFile(fmu_path) as source, \
            zipfile.ZipFile(rewritten, "w", zipfile.ZIP_DEFLATED) as target:
        names = source.namelist()
        for platform, suffix in PLATFORMS.items():
            binary = f"binaries/{platform}/{model_identifier}{suffix}"
            if binary not in names:
                continue
            build = fronts.builds.get(platform)
            if build is not None and build.library is None and platform == "win64":
                continue  # left out: no front for it
            entries.append(_entry(platform, binary, bool(build and build.library),
                                  ("", "") if platform in fronts.prebuilt else fronts.libpython,
                                  platform in fronts.prebuilt))
        kept = {entry.binary: entry for entry in entries}
        keep_win64 = any(entry.platform == "win64" for entry in entries)
        for item in source.infolist():
            name = item.filename
            if name.startswith("binaries/win64/") and not keep_win64:
                continue
            data = source.read(name)
            if name == "modelDescription.xml":
                data = annotate(data.decode("utf-8"), entries).encode("utf-8")
            entry = kept.get(name)
            if entry is not None and entry.front:
                backend = zipfile.ZipInfo(_backend(name), item.date_time)
                backend.external_attr = item.external_attr
                target.writestr(backend, data, zipfile.ZIP_DEFLATED)
                data = fronts.builds[entry.platform].library
            info = zipfile.ZipInfo(name, item.date_time)
            info.external_attr = item.external_attr
            target.writestr(info, data, zipfile.ZIP_DEFLATED)
    shutil.move(str(rewritten), str(fmu_path))
    return entries


def _backend(binary):
    """The name pythonfmu's binary ``binaries/<platform>/<model>.<suffix>`` gets behind the front."""
    stem, dot, suffix = binary.rpartition(".")
    return f"{stem}{_BACKEND}{dot}{suffix}"


def remove_front(fmu_path, destination):
    """Write to ``destination`` a copy of the FMU ``fmu_path`` whose binaries are pythonfmu's
    own again, and whose model description has no platform annotation (the inverse of
    :func:`install_fronts`: the FMU as pythonfmu wrote it, with win64 if it was kept).

    Returns ``destination``.
    """
    with zipfile.ZipFile(fmu_path) as source, \
            zipfile.ZipFile(destination, "w", zipfile.ZIP_DEFLATED) as target:
        names = set(source.namelist())
        for item in source.infolist():
            name = item.filename
            if any(name.endswith(f"{_BACKEND}{suffix}") for suffix in PLATFORMS.values()):
                continue
            backend = _backend(name) if name.startswith("binaries/") else None
            data = source.read(backend if backend in names else name)
            if name == "modelDescription.xml":
                data = annotate(data.decode("utf-8"), None).encode("utf-8")
            target.writestr(item, data)
    return destination


_STUB = '''"""The module pythonfmu loads: {name} itself is in {package}.{script}.

pythonfmu 0.7.0 (findClass) executes this file again at every fmi2Instantiate, with this
module's dict as globals, never frees the list it makes of each class's bases (the class
in it), and releases the dict once too often. A class defined here would stay in memory once
per instance (about 12 KiB); an imported one is the same class every time. Each run takes
one reference to the dict that nothing releases, for the one pythonfmu releases: a list
holding the dict would release them all when the interpreter clears it at exit, freeing the
dict under its module (a heap corruption at exit). Where libpython's symbols are not global
(pythonfmu without the C front), the list is the fallback.
"""
from {package}.{script} import {name}  # noqa: F401

try:
    import ctypes as _ctypes
    _ctypes.pythonapi.Py_IncRef(_ctypes.py_object(globals()))
except (AttributeError, OSError):
    globals().setdefault("_pythonfmu_runs", []).append(globals())
'''


def stage_slave_module(stage, module, package, script, text):
    """Write the slave script ``text`` as ``stage/package/script.py`` and, as the module
    pythonfmu loads, ``stage/module.py``, which imports its one class from there; returns
    the path of ``module.py`` (pythonfmu's script).

    pythonfmu runs the file it loads again for every instance (see the module written):
    the class must live elsewhere for an instance to leave no class behind.
    """
    classes = re.findall(r"^class (\w+)\(", text, flags=re.M)
    if len(classes) != 1:
        raise ValueError(f"{script}: a slave script defines exactly one class, found {classes or 'none'}")
    (Path(stage) / package / f"{script}.py").write_text(text, encoding="utf-8")
    stub = Path(stage) / f"{module}.py"
    stub.write_text(_STUB.format(name=classes[0], package=package, script=script), encoding="utf-8")
    return stub
