"""The FMI 2.0 co-simulation calling sequence, as the slave sees it (standard, section 4.2.4).

Which pythonfmu callback is legal in which state, and which variable may be set in which
state. Standard library only: the FMUs ship it.

**Choices** where the table is stricter than FMI hosts in practice (documented in
docs/fmus.md): inputs may be set in the *instantiated* state too (fmpy and the Reference
FMUs do so; an input has a start value, so nothing is undefined); any variable may be
read in Initialization Mode, not only the outputs; a discarded step leaves the instance
in *stepComplete* (as in the Reference FMUs), so the master may fix its inputs and retry.
The *error* state is entered only when an internal invariant breaks (a non-finite output
from a step that was accepted); every refused call leaves the state as it was.
"""
__all__ = ["INSTANTIATED", "INITIALIZATION", "STEP_COMPLETE", "TERMINATED", "ERROR", "STATES",
           "ALLOWED", "setting_refusal"]

INSTANTIATED = "instantiated"
INITIALIZATION = "Initialization Mode"
STEP_COMPLETE = "stepComplete"
TERMINATED = "terminated"
ERROR = "error"
STATES = (INSTANTIATED, INITIALIZATION, STEP_COMPLETE, TERMINATED, ERROR)

_ALL = frozenset(STATES)
_READABLE = frozenset((INITIALIZATION, STEP_COMPLETE, TERMINATED, ERROR))

# FMI function -> states in which it may be called (the functions that reach the slave)
ALLOWED = {
    "fmi2SetupExperiment": frozenset((INSTANTIATED,)),
    "fmi2EnterInitializationMode": frozenset((INSTANTIATED,)),
    "fmi2ExitInitializationMode": frozenset((INITIALIZATION,)),
    "fmi2DoStep": frozenset((STEP_COMPLETE,)),
    "fmi2Terminate": frozenset((STEP_COMPLETE,)),
    "fmi2Get": _READABLE,
    "fmi2Set": frozenset((INSTANTIATED, INITIALIZATION, STEP_COMPLETE)),
    "fmi2GetFMUstate": _ALL,
    "fmi2SetFMUstate": _ALL,
}

# (causality, variability) -> states in which such a variable may be set
_SETTABLE = {
    ("input", "continuous"): frozenset((INSTANTIATED, INITIALIZATION, STEP_COMPLETE)),
    ("input", "discrete"): frozenset((INSTANTIATED, INITIALIZATION, STEP_COMPLETE)),
    ("parameter", "fixed"): frozenset((INSTANTIATED, INITIALIZATION)),
    ("parameter", "tunable"): frozenset((INSTANTIATED, INITIALIZATION, STEP_COMPLETE)),
}


def setting_refusal(causality, variability, state):
    """Why a variable of ``causality``/``variability`` cannot be set in ``state``; None if it can."""
    states = _SETTABLE.get((causality, variability))
    if states is None:
        return f"it is {'an' if causality[0] in 'aeiou' else 'a'} {causality}; only inputs and " \
               "parameters can be set"
    if state in states:
        return None
    if causality == "parameter" and variability == "fixed":
        return "it is a fixed parameter; fixed parameters can be set only before " \
               "fmi2ExitInitializationMode"
    return f"the instance is in state '{state}'"
