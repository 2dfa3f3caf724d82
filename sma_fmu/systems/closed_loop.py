"""One scenario's closed loop with the FMUs built in a folder, and names as hosts need them.

The loop itself (components, parameter values, connections, Gauss-Seidel order, outputs)
is :func:`sma_fmu.fmi.loop.system.loop_system`'s, which the fmpy master reads too; the SSP
package (:mod:`.ssp`), the container FMU (:mod:`.container`) and the C master
(:mod:`.c_master`) are all written from it, so they wire and parameterise the loop alike.
The "pi" controller has no compensator (the PI's P_ff input then keeps its start, 0 W); a
scenario with ``[drive] kind = "pwm"`` has a PWM driver between the PI and the plant.
"""
from sma_fmu.fmi.loop.system import loop_system
from sma_fmu.fmi.packaging.fmu_names import default_fmu_paths

__all__ = ["closed_loop", "identifier"]


def identifier(name):
    """``name`` as an identifier (letters, digits, underscores; a letter first), as hosts
    need for system and model names: every other character becomes "_", and a name that
    does not start with a letter gets the prefix "sma_"."""
    text = "".join(character if character.isascii() and character.isalnum() else "_"
                   for character in name)
    return text if text[:1].isalpha() else f"sma_{text}"


def closed_loop(scenario, fmu_dir, reference_text=None):
    """The :class:`~sma_fmu.fmi.loop.system.LoopSystem` of ``scenario`` with the FMUs built in
    ``fmu_dir`` (``reference_text``: the signals' reference, when the caller made it)."""
    return loop_system(scenario, default_fmu_paths(fmu_dir), reference_text=reference_text)
