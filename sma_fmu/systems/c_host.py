"""sma-fmu's C host: a small C program on libcosim's C API, built on first use, run as a process.

It loads an FMU (or an SSP package) the way a C/C++ tool does: through libcosim and the FMI
Library, in a process that is not Python. The program (``c_host/cosim_host.c``) is built
with the system C compiler (``$CC``, else ``cc``) against the libcosimc of the libcosimpy
wheel, once per source and library, into a cache folder.

The FMUs carry a native front library that loads libpython itself (docs/fmus.md), so the
host process needs nothing preloaded: :func:`host_environment` removes LD_PRELOAD, and the
runs show what any C tool sees.
"""
import hashlib
import importlib.util
import os
import re
import shutil
import subprocess
import tempfile
from importlib import resources
from pathlib import Path

__all__ = ["CHostError", "host_environment", "build_c_host", "run_c_host"]

_SOURCE = ("c_host", "cosim_host.c")
_OUTPUT_LINE = re.compile(r"([^=\s]+)=(\S+)")


class CHostError(RuntimeError):
    """The C host could not be built or failed to run; the message says why."""


def host_environment(environment=None):
    """The environment for a C host process: ``environment`` (default os.environ) without
    LD_PRELOAD: the FMUs load libpython themselves."""
    environment = dict(os.environ if environment is None else environment)
    environment.pop("LD_PRELOAD", None)
    return environment


def _libcosimc_folder():
    spec = importlib.util.find_spec("libcosimpy")
    if spec is None or spec.origin is None:
        raise CHostError("the C host needs libcosimc: pip install libcosimpy (Linux x86_64)")
    folder = Path(spec.origin).parent / "libcosimc"
    if not any(folder.glob("libcosimc*")):
        raise CHostError(f"{folder}: no libcosimc library in the libcosimpy installation")
    return folder


def build_c_host(cache=None):
    """Build the C host if needed; returns the path of the executable."""
    source = resources.files("sma_fmu.systems").joinpath(*_SOURCE).read_bytes()
    library = _libcosimc_folder()
    key = hashlib.sha256(source + str(library).encode()).hexdigest()[:12]
    folder = Path(cache or tempfile.gettempdir()) / f"sma-fmu-c-host-{key}"
    executable = folder / "cosim_host"
    if executable.is_file():
        return executable
    compiler = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if not compiler:
        raise CHostError("no C compiler to build the C host: install gcc or set CC")
    folder.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=folder) as stage:
        source_file = Path(stage) / _SOURCE[1]
        source_file.write_bytes(source)
        built = Path(stage) / "cosim_host"
        result = subprocess.run(
            [compiler, "-O1", "-Wall", "-o", str(built), str(source_file), f"-L{library}",
             "-lcosimc", f"-Wl,-rpath,{library}"], capture_output=True, text=True)
        if result.returncode != 0:
            raise CHostError(f"{compiler} could not build the C host: {result.stderr.strip()}")
        os.replace(built, executable)  # atomic: a parallel build never sees half a file
    return executable


def run_c_host(kind, path, step_size, steps, timeout=600):
    """Run ``path`` ("fmu" or "ssp" ``kind``) in the C host; returns {"slave.variable": value}.

    ``step_size`` [s], ``steps``: the fixed steps to take. Raises :class:`CHostError` with
    the host's message when it fails.
    """
    executable = build_c_host()
    result = subprocess.run([str(executable), kind, str(path), repr(float(step_size)), str(steps)],
                            capture_output=True, text=True, env=host_environment(),
                            timeout=timeout)
    if result.returncode != 0:
        message = (result.stderr.strip() or result.stdout.strip()).splitlines()
        raise CHostError(f"C host (libcosim) on {path}: exit status {result.returncode}: "
                         f"{message[-1] if message else 'no message'}")
    values = {}
    for line in result.stdout.splitlines():  # libcosim also logs to stdout
        match = _OUTPUT_LINE.fullmatch(line.strip())
        if match:
            values[match.group(1)] = float(match.group(2))
    return values
