"""A small C program compiled with the C family's runtime sources (equal to the Python runtime
to the double): the C master's stroke table (:mod:`sma_fmu.cosim.stroke_table`) and the
bench's timing programs (``sma_fmu/bench/*_timing.c``).

:func:`runtime_program` compiles one with the system C compiler, no fused multiply-add (as the
C family's own builds), the generated parameter table and the source's own folder on the
include path (a timing program's shared header), into a cache folder under a key of every
input, so each is compiled once per source and compiler.
"""
import hashlib
import math
import tempfile
from pathlib import Path

from sma_fmu.fmi.hosts import build_once, c_compiler
from sma_fmu.fmi.packaging.parameter_table import generated_folder
from sma_fmu.runtime.parameters import PARAMETER_SPECS

__all__ = ["RUNTIME", "runtime_program", "wire_numbers"]

RUNTIME = Path(__file__).parents[1] / "c_family" / "runtime"   # the C runtime's sources
_FLAGS = ["-std=c99", "-O2", "-ffp-contract=off"]


def runtime_program(source, cache=None, headers=()):
    """Compile ``source`` (a .c file with a ``main``) with the C runtime's sources if needed;
    the executable's path. ``headers``: files beside ``source`` it includes (part of the key).
    ``cache``: the folder to keep it in (default: the temporary folder). Raises
    :class:`~sma_fmu.fmi.hosts.CHostError` with the compiler's message when it cannot be built."""
    source = Path(source)
    compiler, generated = c_compiler(), generated_folder()
    inputs = [source, *(source.parent / name for name in headers),
              *sorted(RUNTIME.glob("*.[ch]")),
              *sorted(p for p in generated.iterdir() if not p.name.startswith("."))]
    digest = hashlib.sha256("\0".join([*compiler, *_FLAGS]).encode())
    for path in inputs:
        digest.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    executable = (Path(cache or tempfile.gettempdir())
                  / f"sma-fmu-{source.stem}-{digest.hexdigest()[:12]}" / source.stem)
    return build_once(executable, lambda built: [
        *compiler, *_FLAGS, f"-I{source.parent}", f"-I{RUNTIME}", f"-I{generated}", "-o",
        str(built), str(source), *map(str, sorted(RUNTIME.glob("*.c"))), "-lm"], compiler,
        timeout=600)


def wire_numbers(params):
    """The wire's values in PARAMETER_SPECS order as floats, NaN for a value not given: what
    every runtime program reads first (``wire_parameters_from_values``)."""
    return [math.nan if value is None else float(value)
            for value in (getattr(params, spec.name) for spec in PARAMETER_SPECS)]
