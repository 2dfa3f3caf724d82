"""Two small C programs that run FMUs the way non-Python tools do (package data), and their build.

- ``fmi_host.c``: a plain ``dlopen`` FMI 2.0 co-simulation host driven by commands on
  stdin (the tests' fuzz suite, C-host checks and the benchmark's per-step timing);
- ``loop_host.c``: a sequential (Gauss-Seidel) loop of FMUs in one process, as an
  embedded master runs them; in its binary mode the C master of ``sma-fmu run --master c``
  (:mod:`sma_fmu.systems.c_master`);
- ``host_platform.h``: what the dlopen hosts share (loading a binary, the platform shim,
  the FMI 2.0 types of the standard's headers in ``fmi/c_common/include/``);
- ``cosim_host.c``: sma-fmu's C host on libcosim's C API (libcosimc, from the libcosimpy
  wheel): runs an FMU or an SSP package (``sma-fmu check``, the tests, the benchmark).

They link no libpython and need no environment variable: what they show is what any C
host sees. :func:`compile_host` builds either with the system C compiler
(:func:`c_compiler`), where its source is, with this folder and the standard's FMI headers
on the include path, once per source, compiler and library, into a cache folder; with
``windows=True`` it cross-builds ``fmi_host.exe`` with mingw-w64 (:func:`windows_compiler`),
a Windows host for the win64 front (the tests run it under wine).
"""
import hashlib
import importlib.util
import os
import shlex
import shutil
import subprocess
import tempfile
from pathlib import Path

from sma_fmu.console.interrupts import run_child
from sma_fmu.fmi.c_common import FMI_HEADERS, include_flags

__all__ = ["CHostError", "HOST_PROGRAMS", "SHARED_HEADER", "PREBUILT_HOSTS", "c_compiler",
           "windows_compiler", "compile_host", "build_once", "prebuilt_host", "write_prebuilt_hosts"]

HOST_PROGRAMS = ("fmi_host", "cosim_host", "loop_host")
SHARED_HEADER = "host_platform.h"   # loading a binary, the platform shim (fmi_host, loop_host)
HOSTS = Path(__file__).parent       # the hosts' sources
_FLAGS = ["-std=c11", "-O2", "-Wall", "-Wextra", "-Werror"]
PREBUILT_HOSTS = Path(__file__).parent / "prebuilt"  # the wheel's (write_prebuilt_hosts)
# from site-packages/sma_fmu/fmi/hosts/prebuilt/ to site-packages/libcosimpy/libcosimc/
_RELATIVE_LIBCOSIMC = "$ORIGIN/../../../../libcosimpy/libcosimc"


class CHostError(RuntimeError):
    """A C host could not be built or failed to run; the message says why."""


def c_compiler():
    """The C compiler command as a list: ``$CC`` split like a shell would (``CC="ccache gcc"``),
    else ``cc``, else ``gcc``, else ``["cc"]`` (whose failure to run then names it)."""
    if os.environ.get("CC"):
        return shlex.split(os.environ["CC"])
    return ["gcc" if shutil.which("cc") is None and shutil.which("gcc") else "cc"]


def windows_compiler():
    """The mingw-w64 cross compiler as a list: ``$SMA_FMU_WIN64_CC`` split like a shell would,
    else ``x86_64-w64-mingw32-gcc`` (Debian: ``apt-get install gcc-mingw-w64-x86-64``)."""
    return shlex.split(os.environ.get("SMA_FMU_WIN64_CC") or "x86_64-w64-mingw32-gcc")


def _libcosimc_folder():
    """The folder of libcosimc in the libcosimpy installation."""
    spec = importlib.util.find_spec("libcosimpy")
    if spec is None or spec.origin is None:
        raise CHostError("the C host needs libcosimc: pip install libcosimpy (Linux x86_64)")
    folder = Path(spec.origin).parent / "libcosimc"
    if not any(folder.glob("libcosimc*")):
        raise CHostError(f"{folder}: no libcosimc library in the libcosimpy installation")
    return folder


def _link_flags(name, windows=False):
    if windows:
        if name == "cosim_host":
            raise CHostError(f"only fmi_host and loop_host are built for Windows, not {name}")
        return ["-static-libgcc", "-D__USE_MINGW_ANSI_STDIO=1"]
    if name in ("fmi_host", "loop_host"):  # loop_host.c: a sequential loop of FMUs
        return ["-ldl"]
    library = _libcosimc_folder()
    return [f"-L{library}", "-lcosimc", f"-Wl,-rpath,{library}"]


def compile_host(name, cache=None, windows=False):
    """Build the C host ``name`` (one of :data:`HOST_PROGRAMS`) if needed; returns its path.

    The executable is kept in ``cache`` (default: the temporary folder) under a key of the
    source, the compiler and the flags, so each is compiled once. ``windows``: cross-build
    ``<name>.exe`` (fmi_host only) with :func:`windows_compiler`. Raises
    :class:`CHostError` with the compiler's message when it cannot be built.
    """
    if name not in HOST_PROGRAMS:
        raise ValueError(f"C host must be one of {', '.join(HOST_PROGRAMS)}, got {name!r}")
    compiler = windows_compiler() if windows else c_compiler()
    if not windows and shutil.which(compiler[0]) is None:
        prebuilt = prebuilt_host(name)
        if prebuilt is not None:  # no compiler here: the wheel's host of the same source
            return prebuilt
    link = _link_flags(name, windows)
    key = hashlib.sha256(_inputs(name) + "\0".join([*compiler, *_FLAGS, *link]).encode()).hexdigest()[:12]
    hint = "install gcc-mingw-w64-x86-64 or set SMA_FMU_WIN64_CC" if windows else "install gcc or set CC"
    return build_once(
        Path(cache or tempfile.gettempdir()) / f"sma-fmu-{name}-{key}" / (f"{name}.exe" if windows else name),
        lambda built: [*compiler, *_FLAGS, *include_flags(HOSTS), "-o", str(built),
                       str(HOSTS / f"{name}.c"), *link], compiler, hint)


def build_once(executable, command, compiler, hint="install gcc or set CC", timeout=300):
    """``executable`` (a Path in a folder named by a key of its inputs) if it exists, else
    built by ``command(path)`` (the compiler's command line writing ``path``) into a stage
    beside it and moved into place at once, so a parallel build never sees half a file.
    Raises :class:`CHostError` naming ``compiler`` (with ``hint`` when it cannot run, the
    compiler's message when it fails)."""
    if executable.is_file():
        return executable
    executable.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=executable.parent) as stage:
        built = Path(stage) / executable.name
        try:
            result = run_child(command(built), text=True, timeout=timeout, own_temp=True)
        except (OSError, subprocess.SubprocessError) as error:
            raise CHostError(f"C compiler {shlex.join(compiler)!r} could not run to build "
                             f"{executable.stem} ({error}): {hint}") from None
        if result.returncode != 0:
            raise CHostError(f"C compiler {shlex.join(compiler)!r} could not build "
                             f"{executable.stem}: {result.stderr.strip()}")
        os.replace(built, executable)
    return executable


def _inputs(name):
    """The bytes host ``name`` is compiled from: its source, the shared header and the
    standard's FMI 2.0 headers."""
    headers = sorted(FMI_HEADERS.glob("fmi2*.h"))
    return b"\0".join(path.read_bytes() for path in [HOSTS / f"{name}.c", HOSTS / SHARED_HEADER, *headers])


def _source_digest(name):
    return hashlib.sha256(_inputs(name)).hexdigest()


def prebuilt_host(name, folder=None):
    """The wheel's prebuilt ``name`` (Linux x86-64) if it was built from this source, else None."""
    import json

    folder = Path(PREBUILT_HOSTS if folder is None else folder)
    try:
        manifest = json.loads((folder / "manifest.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    path = folder / name
    if manifest.get(name) != _source_digest(name) or not os.access(path, os.X_OK):
        return None
    return path


def write_prebuilt_hosts(folder=None):
    """Compile the three hosts for the wheel into ``folder`` (default :data:`PREBUILT_HOSTS`),
    cosim_host finding libcosimc relative to itself in site-packages; returns the folder."""
    import json

    folder = Path(PREBUILT_HOSTS if folder is None else folder)
    folder.mkdir(parents=True, exist_ok=True)
    manifest = {}
    for name in HOST_PROGRAMS:
        built = compile_host(name, folder / ".cache")
        if name == "cosim_host":  # again, with an rpath that holds where the wheel installs it
            library = _libcosimc_folder()
            command = [*c_compiler(), *_FLAGS, *include_flags(HOSTS), "-o", str(folder / name),
                       str(HOSTS / f"{name}.c"), f"-L{library}",
                       "-lcosimc", f"-Wl,-rpath,{_RELATIVE_LIBCOSIMC}"]
            result = run_child(command, text=True, timeout=300, own_temp=True)
            if result.returncode != 0:
                raise CHostError(f"could not build the prebuilt cosim_host: {result.stderr.strip()}")
        else:
            shutil.copyfile(built, folder / name)
        (folder / name).chmod(0o755)
        manifest[name] = _source_digest(name)
    shutil.rmtree(folder / ".cache", ignore_errors=True)
    (folder / "manifest.json").write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n",
                                          encoding="utf-8")
    return folder
