"""Which wire parameters each FMU uses, and so exposes (standard library only: the FMUs ship it).

An FMU that models the wire exposes every wire parameter its model uses as an FMI
parameter, so a master can set a scenario's whole wire in it and never runs a mix of two
wires (docs/fmus.md, "One wire"). :data:`UNUSED_SECTIONS` says which sections of the schema
(:data:`~sma_fmu.runtime.parameters.PARAMETER_SPECS`) a model does not use, with the few
parameters of those sections it does use; every other parameter is used (a section added
to the schema is exposed, never silently left out). The loop's masters read the same table
(:mod:`sma_fmu.fmi.loop.values`) to know what an FMU must take.

An optional parameter that the parameter file does not give (None in Python) is exposed
with the value NaN, "not given": the FMU then takes the value the model defines in its
place (:data:`~sma_fmu.runtime.model_terms.TERM_DEFAULTS`; alpha: the thermal time
constant; a bound of the data range: none), as the library does. A host may set NaN to
take a given value back. A required parameter is never NaN.
"""
from dataclasses import fields

from sma_fmu.runtime.model_terms import TERM_DEFAULTS
from sma_fmu.runtime.parameters import DATA_RANGE, PARAMETER_SPECS, WireParameters

__all__ = ["WIRE_DIGEST", "UNUSED_SECTIONS", "NULLABLE", "wire_names", "not_given_text"]

WIRE_DIGEST = "wire_digest"   # the String constant every FMU states its wire's digest in

# model -> (sections it does not use, parameters of those sections it uses); a model not
# named here uses no wire parameter (the PI takes Kp and Ki as its gains)
UNUSED_SECTIONS = {
    "SmaActuator": (("constant_temperature", "sensing", "control"), ()),
    "SmaFeedforward": (("constant_temperature", "control"), ("model_load", "alpha", "beta")),
}
_DEFAULTS = dict(TERM_DEFAULTS)
# the optional parameters that may be not given (None in Python: NaN in an FMU)
NULLABLE = frozenset(f.name for f in fields(WireParameters) if f.init and f.default is None
                     and any(spec.name == f.name for spec in PARAMETER_SPECS))


def wire_names(model):
    """The names of the wire parameters ``model`` uses, in PARAMETER_SPECS order."""
    if model not in UNUSED_SECTIONS:
        return ()
    sections, kept = UNUSED_SECTIONS[model]
    return tuple(spec.name for spec in PARAMETER_SPECS
                 if spec.section not in sections or spec.name in kept)


def not_given_text(name):
    """What NaN means in the optional parameter ``name``: not given, and what the model
    takes in its place."""
    if name == "alpha":
        return "NaN: not given, the model then takes the thermal time constant tau_th"
    if name in DATA_RANGE:
        return "NaN: not given, the data range has no bound on this side"
    default = _DEFAULTS.get(name)
    if isinstance(default, str):
        return f"NaN: not given, the model then takes the value of {default}"
    if default is None:
        return "NaN: not given (unused while second_stage.w2 = 0, required when w2 > 0)"
    return f"NaN: not given, the model then takes {float(default)!r}"
