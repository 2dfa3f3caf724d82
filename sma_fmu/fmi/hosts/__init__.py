"""Two small C programs that run FMUs the way non-Python tools do (package data).

- ``fmi_host.c``: a plain ``dlopen`` FMI 2.0 co-simulation host driven by commands on
  stdin (the tests' fuzz suite, C-host checks and the benchmark's per-step timing);
- ``cosim_run.c``: a run through libcosim's C API (from the libcosimpy wheel, a test extra).

They link no libpython and need no environment variable: what they show is what any C
host sees.
"""
import os
import shutil
import subprocess
from importlib import resources
from pathlib import Path

__all__ = ["compile_host", "compile_cosim_run"]


def _compiler():
    compiler = shutil.which(os.environ.get("CC") or "cc") or shutil.which("gcc")
    if compiler is None:
        raise FileNotFoundError("no C compiler found (set CC)")
    return compiler


def _compile(name, folder, flags):
    exe = Path(folder) / name
    with resources.as_file(resources.files(__name__) / f"{name}.c") as source:
        subprocess.run([_compiler(), "-std=c11", "-O2", "-Wall", "-Wextra", "-Werror", "-o", str(exe),
                        str(source), *flags], check=True, capture_output=True)
    return exe


def compile_host(folder):
    """Compile ``fmi_host.c`` into ``folder``; returns the executable's path."""
    return _compile("fmi_host", folder, ["-ldl"])


def compile_cosim_run(folder):
    """Compile ``cosim_run.c`` against libcosimpy's libcosimc; None if libcosimpy is missing."""
    try:
        import libcosimpy
    except ImportError:
        return None
    library = Path(libcosimpy.__file__).parent / "libcosimc"
    return _compile("cosim_run", folder, [f"-L{library}", "-lcosimc", f"-Wl,-rpath,{library}"])
