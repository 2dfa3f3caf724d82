"""Settings that are a choice among names, carried by FMI Integer parameters (standard library only).

Every SSP host binds Integer parameters (libcosim, Ecos, OMSimulator, fmpy), but
OMSimulator binds no String parameters and fmpy's ``simulate_ssp`` binds nothing. So a
setting that picks one of a few names is an Integer parameter holding the *code* of the
name, as an FMI 2.0 Enumeration would (pythonfmu 0.7.0 declares no Enumerations, and SSP
1.0 binds an Enumeration by item name, which these hosts do not read). Codes start at 1,
as Enumeration items usually do, so 0, the value of a parameter no one set, is no choice.

The library path and scenario files keep the names; :func:`choice_code` and
:func:`choice_name` translate at the FMU's boundary.
"""
__all__ = ["CHOICES", "choice_code", "choice_name", "choice_text"]

# parameter -> {code: name}
CHOICES = {
    "hysteresis_mode": {1: "continuous", 2: "switch"},
    "inverse": {1: "major", 2: "minor-loop"},
    "shaping": {1: "none", 2: "reachable"},
    "modulation": {1: "pwm", 2: "linear"},   # the driver: switched, or the demand itself
}


def choice_text(parameter):
    """The mapping of ``parameter`` as text: ``1 = continuous, 2 = switch``."""
    return ", ".join(f"{code} = {name}" for code, name in CHOICES[parameter].items())


def choice_code(parameter, name):
    """The Integer code of ``name`` for ``parameter``; ``ValueError`` naming both if unknown."""
    for code, known in CHOICES[parameter].items():
        if name == known:
            return code
    names = ", ".join(CHOICES[parameter].values())
    raise ValueError(f"{parameter} must be one of {names}, got {name!r}")


def choice_name(parameter, code):
    """The name of Integer ``code`` for ``parameter``; ``ValueError`` naming both if unknown."""
    if isinstance(code, int) and not isinstance(code, bool) and code in CHOICES[parameter]:
        return CHOICES[parameter][code]
    raise ValueError(f"{parameter} must be {_alternatives(parameter)}, got {code!r}")


def _alternatives(parameter):
    items = [f"{code} ({name})" for code, name in CHOICES[parameter].items()]
    return " or ".join(items) if len(items) < 3 else ", ".join(items[:-1]) + f" or {items[-1]}"
