"""Compile C runtime modules (sma_fmu/fmi/c_family/runtime) for the equality tests.

:func:`compile_runtime` builds a list of runtime modules (base names, ``"plant"`` for
plant.c) into a shared library with gcc and the C family's flags (docs: notes on the C
contract: C99, -Wall -Wextra -Wpedantic -Werror, -ffp-contract=off so no fused multiply-add
changes the last bits) and loads it with ctypes. :func:`compile_win64` compiles the same
files with mingw-w64 under the same flags, to prove the win64 build is clean.
"""
import ctypes
import shutil
import subprocess
from pathlib import Path

from system_needs import need

RUNTIME_DIR = Path(__file__).resolve().parent.parent / "sma_fmu" / "fmi" / "c_family" / "runtime"
FLAGS = ("-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-ffp-contract=off", "-O2")
MINGW = "x86_64-w64-mingw32-gcc"


def _sources(modules):
    sources = [RUNTIME_DIR / f"{module}.c" for module in modules]
    missing = [str(path) for path in sources if not path.is_file()]
    if missing:
        raise FileNotFoundError(f"no C runtime module {', '.join(missing)}")
    return sources


def _run(command):
    result = subprocess.run([str(part) for part in command], capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, command))} failed:\n{result.stderr}")


def compile_runtime(modules, folder, extra_source=None, name="runtime"):
    """The runtime ``modules`` (and ``extra_source``, C text such as a test-only shim that
    includes runtime headers) built with gcc into ``folder``/lib<name>.so; a ctypes.CDLL."""
    need("gcc")  # skipped without it, failed under CI=true (tests/system_needs.py)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    sources = _sources(modules)
    if extra_source is not None:
        shim = folder / f"{name}_shim.c"
        shim.write_text(extra_source)
        sources.append(shim)
    library = folder / f"lib{name}.so"
    _run(["gcc", *FLAGS, "-fPIC", "-shared", "-I", RUNTIME_DIR, "-o", library, *sources, "-lm"])
    return ctypes.CDLL(str(library))


def compile_win64(modules, folder):
    """Compile the runtime ``modules`` to win64 objects with mingw-w64 under the same flags
    (-c, no link); returns the object paths, or None when mingw-w64 is not installed."""
    need("mingw-w64")  # skipped without it, failed under CI=true (tests/system_needs.py)
    if shutil.which(MINGW) is None:
        return None
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    objects = []
    for source in _sources(modules):
        target = folder / f"{source.stem}.obj"
        _run([MINGW, *FLAGS, "-c", "-o", target, source])
        objects.append(target)
    return objects
