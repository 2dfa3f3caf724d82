"""Two small C programs that run FMUs the way non-Python tools do (package data), and their build.

- ``fmi_host.c``: a plain ``dlopen`` FMI 2.0 co-simulation host driven by commands on
  stdin (the tests' fuzz suite, C-host checks and the benchmark's per-step timing);
- ``cosim_host.c``: sma-fmu's C host on libcosim's C API (libcosimc, from the libcosimpy
  wheel): runs an FMU or an SSP package (``sma-fmu check``, the tests, the benchmark).

They link no libpython and need no environment variable: what they show is what any C
host sees. :func:`compile_host` builds either with the system C compiler
(:func:`c_compiler`), once per source, compiler and library, into a cache folder.
"""
import hashlib
import importlib.util
import os
import shlex
import shutil
import subprocess
import tempfile
from importlib import resources
from pathlib import Path

__all__ = ["CHostError", "HOST_PROGRAMS", "c_compiler", "compile_host"]

HOST_PROGRAMS = ("fmi_host", "cosim_host")
_FLAGS = ["-std=c11", "-O2", "-Wall", "-Wextra", "-Werror"]


class CHostError(RuntimeError):
    """A C host could not be built or failed to run; the message says why."""


def c_compiler():
    """The C compiler command as a list: ``$CC`` split like a shell would (``CC="ccache gcc"``),
    else ``cc``, else ``gcc``, else ``["cc"]`` (whose failure to run then names it)."""
    if os.environ.get("CC"):
        return shlex.split(os.environ["CC"])
    return ["gcc" if shutil.which("cc") is None and shutil.which("gcc") else "cc"]


def _libcosimc_folder():
    """The folder of libcosimc in the libcosimpy installation."""
    spec = importlib.util.find_spec("libcosimpy")
    if spec is None or spec.origin is None:
        raise CHostError("the C host needs libcosimc: pip install libcosimpy (Linux x86_64)")
    folder = Path(spec.origin).parent / "libcosimc"
    if not any(folder.glob("libcosimc*")):
        raise CHostError(f"{folder}: no libcosimc library in the libcosimpy installation")
    return folder


def _link_flags(name):
    if name == "fmi_host":
        return ["-ldl"]
    library = _libcosimc_folder()
    return [f"-L{library}", "-lcosimc", f"-Wl,-rpath,{library}"]


def compile_host(name, cache=None):
    """Build the C host ``name`` (one of :data:`HOST_PROGRAMS`) if needed; returns its path.

    The executable is kept in ``cache`` (default: the temporary folder) under a key of the
    source, the compiler and the flags, so each is compiled once. Raises
    :class:`CHostError` with the compiler's message when it cannot be built.
    """
    if name not in HOST_PROGRAMS:
        raise ValueError(f"C host must be one of {', '.join(HOST_PROGRAMS)}, got {name!r}")
    source = resources.files(__name__).joinpath(f"{name}.c").read_bytes()
    compiler, link = c_compiler(), _link_flags(name)
    key = hashlib.sha256(source + "\0".join([*compiler, *_FLAGS, *link]).encode()).hexdigest()[:12]
    folder = Path(cache or tempfile.gettempdir()) / f"sma-fmu-{name}-{key}"
    executable = folder / name
    if executable.is_file():
        return executable
    folder.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=folder) as stage:
        source_file = Path(stage) / f"{name}.c"
        source_file.write_bytes(source)
        built = Path(stage) / name
        command = [*compiler, *_FLAGS, "-o", str(built), str(source_file), *link]
        try:
            result = subprocess.run(command, capture_output=True, text=True, timeout=300)
        except (OSError, subprocess.SubprocessError) as error:
            raise CHostError(f"C compiler {shlex.join(compiler)!r} could not run to build "
                             f"{name} ({error}): install gcc or set CC") from None
        if result.returncode != 0:
            raise CHostError(f"C compiler {shlex.join(compiler)!r} could not build {name}: "
                             f"{result.stderr.strip()}")
        os.replace(built, executable)  # atomic: a parallel build never sees half a file
    return executable
