"""The native front of the FMUs: compiled by the build with the system C compiler.

pythonfmu's binary needs libpython preloaded in C hosts, crashes on some resource URIs,
passes log messages to the host as printf formats and cannot report fmi2Error for a
refused call. The front (C sources in ``sma_fmu/fmi/native/``, shipped with the package)
fixes that: it becomes ``binaries/linux64/<model>.so`` and forwards every call to
pythonfmu's binary, renamed ``<model>_pythonfmu.so`` (see ``native/fmi2_exports.c``).

The compiler is :func:`~sma_fmu.fmi.hosts.c_compiler` (``$CC``, default ``cc``). It
records the shared libpython of the Python running the build, so a C host finds one
without any environment variable. Where no
compiler works the FMU keeps pythonfmu's plain binary and the build says so
(:class:`NativeFrontWarning`); docs/fmus.md lists what is then lost.
"""
import hashlib
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import zipfile
from importlib import resources
from pathlib import Path

from sma_fmu.fmi.hosts import c_compiler

__all__ = ["NativeFrontWarning", "FrontBuild", "compile_front", "install_front", "remove_front",
           "libpython_path"]

_PLATFORM = "linux64"
_BACKEND_SUFFIX = "_pythonfmu.so"
_FLAGS = ["-std=c11", "-O2", "-fPIC", "-shared", "-fvisibility=hidden", "-Wall",
          "-Wl,-z,nodelete", "-Wl,--no-undefined"]
_LIBRARIES = ["-ldl", "-lpthread"]
_compiled = {}  # (compiler, sources digest, libpython) -> bytes of the library


class NativeFrontWarning(UserWarning):
    """The FMUs were built without the native front (no C compiler, or not Linux x86-64)."""


class FrontBuild:
    """A compiled front (``library`` bytes) or the reason there is none (``problem``)."""

    def __init__(self, library=None, problem=None):
        self.library, self.problem = library, problem


def libpython_path():
    """(absolute path or "", soname) of this Python's shared libpython, as sysconfig says."""
    soname = sysconfig.get_config_var("INSTSONAME") or ""
    if not (soname.startswith("libpython") and ".so" in soname):  # a static build
        soname = f"libpython{sys.version_info[0]}.{sys.version_info[1]}.so.1.0"
    path = Path(sysconfig.get_config_var("LIBDIR") or "/nonexistent") / soname
    return (str(path) if path.is_file() else ""), soname


def _sources():
    """{file name: bytes} of the shipped C sources and headers."""
    folder = resources.files("sma_fmu.fmi") / "native"
    return {entry.name: entry.read_bytes() for entry in folder.iterdir()
            if entry.name.endswith((".c", ".h"))}


def compile_front(libpython=None):
    """Compile the front once per process and compiler; returns a :class:`FrontBuild`.

    ``libpython`` is the (path, soname) the front tries when the host has no Python;
    default :func:`libpython_path` (the Python running the build).
    """
    if not (sys.platform.startswith("linux") and sys.maxsize > 2 ** 32):
        return FrontBuild(problem=f"the native front is built for Linux x86-64 only (this is {sys.platform})")
    compiler = c_compiler()
    sources = _sources()
    library_path, soname = libpython_path() if libpython is None else libpython
    digest = hashlib.sha256(b"".join(name.encode() + data for name, data in sorted(sources.items())))
    key = (tuple(compiler), digest.hexdigest(), library_path, soname)
    if key not in _compiled:
        _compiled[key] = _compile(compiler, sources, library_path, soname)
    return _compiled[key]


def _compile(compiler, sources, library_path, soname):
    with tempfile.TemporaryDirectory(prefix="sma_fmu_front_") as folder:
        for name, data in sources.items():
            (Path(folder) / name).write_bytes(data)
        output = Path(folder) / "front.so"
        command = [*compiler, *_FLAGS, f'-DSMA_FRONT_LIBPYTHON="{library_path}"',
                   f'-DSMA_FRONT_LIBPYTHON_SONAME="{soname}"', "-o", str(output),
                   *sorted(str(Path(folder) / n) for n in sources if n.endswith(".c")), *_LIBRARIES]
        try:
            result = subprocess.run(command, capture_output=True, text=True, timeout=300)
        except (OSError, subprocess.SubprocessError) as error:
            return FrontBuild(problem=f"C compiler {' '.join(compiler)!r} could not run ({error})")
        if result.returncode != 0 or not output.is_file():
            last = (result.stderr.strip().splitlines() or ["no message"])[-1]
            return FrontBuild(problem=f"C compiler {' '.join(compiler)!r} failed: {last}")
        return FrontBuild(library=output.read_bytes())


def _backend(binary):
    """The name pythonfmu's binary ``binaries/<platform>/<model>.so`` gets behind the front."""
    return binary[:-len(".so")] + _BACKEND_SUFFIX


def install_front(fmu_path, model_identifier, library):
    """Put ``library`` (the front) into the FMU as its binary; pythonfmu's becomes ``*_pythonfmu.so``."""
    fmu_path = Path(fmu_path)
    binary = f"binaries/{_PLATFORM}/{model_identifier}.so"
    backend = _backend(binary)
    rewritten = fmu_path.with_suffix(".front.tmp")
    with zipfile.ZipFile(fmu_path) as source, \
            zipfile.ZipFile(rewritten, "w", zipfile.ZIP_DEFLATED) as target:
        names = source.namelist()
        if binary not in names:
            raise ValueError(f"{fmu_path}: no {binary} to put the native front before")
        for item in source.infolist():
            data = source.read(item.filename)
            if item.filename == binary:
                backend_info = zipfile.ZipInfo(backend, item.date_time)
                backend_info.external_attr = item.external_attr
                target.writestr(backend_info, data, zipfile.ZIP_DEFLATED)
                front_info = zipfile.ZipInfo(binary, item.date_time)
                front_info.external_attr = item.external_attr
                target.writestr(front_info, library, zipfile.ZIP_DEFLATED)
            else:
                target.writestr(item, data)
    shutil.move(str(rewritten), str(fmu_path))


def remove_front(fmu_path, destination):
    """Write to ``destination`` a copy of the FMU ``fmu_path`` whose binaries are pythonfmu's
    own again (the inverse of :func:`install_front`: the FMU as it was before the front).

    Returns ``destination``.
    """
    with zipfile.ZipFile(fmu_path) as source, \
            zipfile.ZipFile(destination, "w", zipfile.ZIP_DEFLATED) as target:
        names = set(source.namelist())
        for item in source.infolist():
            if item.filename.endswith(_BACKEND_SUFFIX):
                continue
            backend = _backend(item.filename) if item.filename.endswith(".so") else None
            target.writestr(item, source.read(backend if backend in names else item.filename))
    return destination
