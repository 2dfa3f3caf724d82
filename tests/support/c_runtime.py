"""Compile C runtime modules (sma_fmu/fmi/c_family/runtime) for the equality tests.

:func:`compile_runtime` builds a list of runtime modules (base names, ``"plant"`` for
plant.c) into a shared library with gcc and the C family's flags (docs: notes on the C
contract: C99, -Wall -Wextra -Wpedantic -Werror, -ffp-contract=off so no fused multiply-add
changes the last bits) and loads it with ctypes. :func:`compile_win64` compiles the same
files with mingw-w64 under the same flags, to prove the win64 build is clean. Both include
the headers generated from the Python schema (:data:`INCLUDES`: the runtime folder and
parameter_table's generated folder), as every build of the C family does.
"""
import ctypes
import shutil
import subprocess
from pathlib import Path

from system_needs import need

from sma_fmu.fmi.packaging.parameter_table import generated_folder

RUNTIME_DIR = Path(__file__).resolve().parents[2] / "sma_fmu" / "fmi" / "c_family" / "runtime"
INCLUDES = ("-I", RUNTIME_DIR, "-I", generated_folder())
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
    need("gcc")  # skipped without it, failed under CI=true (tests/support/system_needs.py)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    sources = _sources(modules)
    if extra_source is not None:
        shim = folder / f"{name}_shim.c"
        shim.write_text(extra_source)
        sources.append(shim)
    library = folder / f"lib{name}.so"
    _run(["gcc", *FLAGS, "-fPIC", "-shared", *INCLUDES, "-o", library, *sources, "-lm"])
    return ctypes.CDLL(str(library))


def load_with_signatures(modules, folder, shim, signatures):
    """:func:`compile_runtime` of ``modules`` and the C text ``shim``, with the ctypes
    (restype, argtypes) of each function named in ``signatures`` set."""
    library = compile_runtime(modules, folder, extra_source=shim)
    for name, (restype, argtypes) in signatures.items():
        function = getattr(library, name)
        function.restype, function.argtypes = restype, argtypes
    return library


def compile_win64(modules, folder):
    """Compile the runtime ``modules`` to win64 objects with mingw-w64 under the same flags
    (-c, no link); returns the object paths, or None when mingw-w64 is not installed."""
    need("mingw-w64")  # skipped without it, failed under CI=true (tests/support/system_needs.py)
    if shutil.which(MINGW) is None:
        return None
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    objects = []
    for source in _sources(modules):
        target = folder / f"{source.stem}.obj"
        _run([MINGW, *FLAGS, *INCLUDES, "-c", "-o", target, source])
        objects.append(target)
    return objects


class StateDoubles:
    """state()/restore() of a C stepper as a flat array of doubles, for the ctypes wrappers
    (c_plant.CPlant, c_feedforward.CStepper): ``STATE_CALLS`` names the library's
    (size, write, read) functions; read refuses with a message, raised as ValueError."""

    STATE_CALLS = ("", "", "")

    def state(self):
        size, write, _ = (getattr(self.lib, name) for name in self.STATE_CALLS)
        out = (ctypes.c_double * size(self.pointer))()
        write(self.pointer, out)
        return list(out)

    def restore(self, values):
        error = ctypes.create_string_buffer(512)
        array = (ctypes.c_double * max(len(values), 1))(*values)
        if getattr(self.lib, self.STATE_CALLS[2])(self.pointer, array, len(values), error):
            raise ValueError(error.value.decode())


def with_reversals(head, reversals):
    """A saved state's doubles: ``head``, then the count and the (T, xi_MF) reversal points."""
    out = list(head) + [float(len(reversals))]
    for temperature, xi_mf in reversals:
        out += [float(temperature), float(xi_mf)]
    return out
