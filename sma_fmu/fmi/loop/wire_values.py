"""The wire a scenario sets in an FMU: its whole wire, or a refusal naming both digests.

An FMU that models the wire exposes every wire parameter its model uses
(:mod:`sma_fmu.fmi.python_family.slave_support.wire_use`), an optional one not given as NaN.
So a master sets the scenario's whole wire in it (:func:`wire_values`) and runs exactly
that wire, whatever wire the FMU was built from. An FMU that cannot take it (built by an
older sma-fmu: without the model terms as parameters, or without NaN for "not given") runs
the scenario only where the values it cannot take are its own already; otherwise
:class:`WireMismatchError` names the FMU, both wires' digests and files, the parameters,
and the way out. Never a mix of two wires.
"""
import json
import math
import zipfile

from sma_fmu.fmi.python_family.slave_support.wire_use import WIRE_DIGEST, wire_names
from sma_fmu.runtime.parameters import ParameterError, WireParameters
from sma_fmu.runtime.wire_identity import wire_digest

__all__ = ["PARAMETERS_ENTRY", "WireMismatchError", "BuiltWire", "built_wire", "wire_values",
           "mismatch_error"]

PARAMETERS_ENTRY = "resources/parameters.json"


class WireMismatchError(ValueError):
    """An FMU cannot take the scenario's wire (see the module)."""


class BuiltWire:
    """The wire an FMU was built from: ``params`` (WireParameters, None if its
    parameters.json cannot be read), ``digest`` and ``source`` (the parameter file's path)."""

    def __init__(self, params, source):
        self.params, self.source = params, source
        self.digest = None if params is None else wire_digest(params)


def built_wire(fmu):
    """The :class:`BuiltWire` of the FMU file ``fmu`` (its resources/parameters.json)."""
    try:
        with zipfile.ZipFile(fmu) as archive:
            document = json.loads(archive.read(PARAMETERS_ENTRY))
        values = {name: entry["value"] for name, entry in document["parameters"].items()}
        source = str(document.get("source", PARAMETERS_ENTRY))
        return BuiltWire(WireParameters.from_values(values, source), source)
    except (OSError, KeyError, TypeError, AttributeError, ValueError, ParameterError,
            zipfile.BadZipFile):
        return BuiltWire(None, f"{fmu}: {PARAMETERS_ENTRY}")


def _is_nan(start):
    """True if a model variable's start (fmpy gives its text) is NaN."""
    try:
        return math.isnan(float(start))
    except (TypeError, ValueError):
        return False


def wire_values(model, variables, wire, read_built):
    """({name: value} of the wire parameters to set in FMU ``model`` with model
    ``variables`` ({name: fmpy ScalarVariable}) so that it runs ``wire`` (a
    :class:`~sma_fmu.runtime.parameters.WireParameters`; NaN: not given), [names it cannot
    take whose value differs from its own]). ``read_built()``: its :class:`BuiltWire`, read
    only when some parameter cannot be set. A NaN is not set where the FMU's start is NaN."""
    takes_nan = WIRE_DIGEST in variables   # an FMU of this version: NaN is "not given"
    values, refused, built = {}, [], None
    for name in wire_names(model):
        value = getattr(wire, name)
        variable = variables.get(name)
        if variable is None or variable.causality != "parameter" or (value is None and not takes_nan):
            built = built or read_built()
            if built.params is None or getattr(built.params, name) != value:
                refused.append(name)
            continue
        if value is None:
            if _is_nan(variable.start):
                continue
            value = math.nan
        values[name] = value
    return values, refused


def mismatch_error(fmu, model, refused, wire_record, built):
    """The :class:`WireMismatchError` of FMU file ``fmu`` (of ``model``) that cannot take
    ``refused`` of the scenario's wire (``wire_record``: {"file", "digest"})."""
    shown = ", ".join(refused[:6]) + (f" and {len(refused) - 6} more" if len(refused) > 6 else "")
    file = wire_record["file"] or "the scenario's parameter file"
    return WireMismatchError(
        f"{fmu}: {model} was built from the wire {built.digest or 'of unknown digest'} "
        f"({built.source}) and cannot take {shown} of the scenario's wire "
        f"{wire_record['digest']} ({file}): it would run a mix of the two. Build the FMUs "
        f"from the scenario's wire: sma-fmu build --model {file} --out DIR")
