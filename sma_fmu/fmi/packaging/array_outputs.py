"""The FMI 3.0 array outputs of the C family: the plant's reversal stack, sized by
``memory_depth``, a structural parameter.

FMI 2.0 has only scalars; in FMI 3.0 SmaActuator shows the stack of its minor-loop memory
(runtime/minor_loops.py, plant.py's ``reversals``: oldest first) as two Float64 arrays of
``memory_depth`` values each, and how many entries are in use. ``memory_depth`` [1] is the
FMI 2.0 parameter of the same name and value reference (the most reversal points the memory
keeps: the physics are FMI 2.0's), declared a UInt64 ``structuralParameter``, settable only
in Configuration Mode within the runtime's bounds. The elements past ``reversal_count`` are
NaN (:data:`UNUSED`). The C side is the adapter's ``get_array``
(fmi/models/SmaActuator/SmaActuator.c), whose array numbers follow :attr:`Arrays.arrays`' order.
"""
from dataclasses import dataclass

from sma_fmu.runtime.parameters import MAX_MEMORY_DEPTH

__all__ = ["Arrays", "ARRAYS", "UNUSED", "MIN_MEMORY_DEPTH"]

MIN_MEMORY_DEPTH = 2  # parameters.py's "depth" rule: a whole number in [2, MAX_MEMORY_DEPTH]
UNUSED = "NaN"        # the value of an element past the live entries


@dataclass(frozen=True)
class Arrays:
    """A model's array outputs: the structural parameter ``size`` (an FMI 2.0 Integer
    parameter) in [``minimum``, ``maximum``], the arrays (name, unit, description) in the
    adapter's order, and the UInt64 output counting the live entries (name, description)."""
    size: str
    minimum: int
    maximum: int
    arrays: tuple
    count: tuple


ARRAYS = {
    "SmaActuator": Arrays(
        "memory_depth", MIN_MEMORY_DEPTH, MAX_MEMORY_DEPTH,
        (("reversal_T", "degC", "temperatures T_i of the reversal stack, oldest first "
          "(return-point memory; NaN past reversal_count)"),
         ("reversal_xi_MF", "1", "xi_MF = xi_M + xi_F at each reversal of the stack, oldest "
          "first (NaN past reversal_count)")),
        ("reversal_count", "reversal points in the stack (0 .. memory_depth; 0 in switch mode)")),
}
