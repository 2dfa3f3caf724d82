"""The native FMUs' model description and variable table, derived from the pythonfmu FMU's.

A native FMU must drop in for its pythonfmu twin (an SSP or a container made with one
family runs with the other), so nothing about its interface is written twice: the model
description is the one ``sma-fmu build`` writes, with only what makes it native changed:

- ``guid`` (:func:`~.reproducible.structural_guid`: the same for every parameter file),
  ``generationTool``, no ``generationDateAndTime``;
- the ``CoSimulation`` element: ``needsExecutionTool="false"``, saved and serialized states,
  and ``<SourceFiles>``;
- the ``start`` of every Real as the exact value the Python slave starts with (``repr``:
  pythonfmu writes 15 digits, so ``41.4726014989086`` becomes ``41.47260149890864``);
- the platforms annotation (:mod:`sma_fmu.fmi.packaging.platforms`): native binaries, no Python.

The C header ``<Model>_variables.h`` (:func:`variables_header`) holds the same variables
(value reference, name, type, causality, variability, unit) as an enum ``VAR_<name>`` and a table
the layer uses: the structure only, so one binary serves every parameter file. The start
values travel in ``resources/model_starts.json`` (:func:`model_starts`): the exact start of
every variable, and the wire parameter file the FMU was built with, in PARAMETER_SPECS order
(null where Python's value is None), for the parameters the FMU does not expose. An adapter
that names a variable the FMU does not have does not compile.
"""
import json
import math
import xml.etree.ElementTree as ET

from sma_fmu import __version__
from sma_fmu.fmi.packaging.reproducible import structural_guid
from sma_fmu.runtime.parameters import PARAMETER_SPECS

__all__ = ["LOG_CATEGORIES", "native_description", "variables_header", "model_starts", "c_string"]

LOG_CATEGORIES = ("logStatusWarning", "logStatusDiscard", "logStatusError", "logStatusFatal",
                  "logAll")
_KINDS = {"Real": "SMA_REAL", "Integer": "SMA_INTEGER", "Boolean": "SMA_BOOLEAN",
          "String": "SMA_STRING"}
_CO_SIMULATION = {"needsExecutionTool": "false", "canHandleVariableCommunicationStepSize": "true",
                  "canInterpolateInputs": "false", "canBeInstantiatedOnlyOncePerProcess": "false",
                  "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true",
                  "canNotUseMemoryManagementFunctions": "true"}


def _variables(root):
    """[(ScalarVariable element, its type element)] in document order."""
    found = []
    for variable in root.find("ModelVariables"):
        typed = next(child for child in variable if child.tag in _KINDS)
        found.append((variable, typed))
    return found


def native_description(python_description, starts, source_files):
    """The native model description (bytes) from the pythonfmu FMU's ``python_description``
    (bytes); ``starts`` {name: exact start value}; ``source_files`` the names in sources/.
    Returns (bytes, guid)."""
    root = ET.fromstring(python_description)
    guid = structural_guid(root, __version__)  # one per structure: reproducible builds
    root.set("guid", guid)
    root.attrib.pop("generationDateAndTime", None)
    root.set("generationTool", f"sma-fmu {__version__} (build --native: C99, no Python)")
    co_simulation = root.find("CoSimulation")
    identifier = co_simulation.get("modelIdentifier")
    co_simulation.attrib.clear()
    co_simulation.set("modelIdentifier", identifier)
    co_simulation.attrib.update(_CO_SIMULATION)
    for child in list(co_simulation):
        co_simulation.remove(child)
    files = ET.SubElement(co_simulation, "SourceFiles")
    for name in source_files:
        ET.SubElement(files, "File", name=name)
    categories = [c.get("name") for c in root.find("LogCategories")]
    if tuple(categories) != LOG_CATEGORIES:
        raise ValueError(f"{root.get('modelName')}: log categories {categories} are not the "
                         f"layer's {list(LOG_CATEGORIES)}")
    for variable, typed in _variables(root):
        if typed.tag == "Real" and typed.get("start") is not None:
            typed.set("start", repr(float(starts[variable.get("name")])))
    vendor = root.find("VendorAnnotations")
    if vendor is not None:
        root.remove(vendor)  # the front's platforms: annotated again for the native binaries
    ET.indent(root, "\t")
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True) + b"\n", guid


def c_string(text):
    """A C expression for ``text`` (UTF-8): a string literal, or, where C99 limits a literal's
    length (4095), a brace-enclosed char list for an array initializer."""
    data = text.encode("utf-8")
    if len(data) > 4000:
        return "{" + ", ".join(str(b) for b in data) + ", 0}"
    out = []
    for byte in data:
        char = chr(byte)
        if char in '"\\?':
            out.append("\\" + char)
        elif 32 <= byte < 127:
            out.append(char)
        else:
            out.append(f"\\{byte:03o}")
    return '"' + "".join(out) + '"'


def _number(value):
    """A C double literal of ``value`` (exact: repr round-trips); NAN for None."""
    if value is None:
        return "NAN"
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"start value {value!r} is not finite")
    return repr(value)


def variables_header(description):
    """Text of ``<Model>_variables.h`` for the native model ``description`` (bytes): the
    structure only (no start value: those are in :func:`model_starts`), so the binary is
    the same for every parameter file."""
    root = ET.fromstring(description)
    model, guid = root.get("modelName"), root.get("guid")
    spec_index = {spec.name: i for i, spec in enumerate(PARAMETER_SPECS)}
    rows, names = [], []
    for variable, typed in _variables(root):
        name = variable.get("name")
        causality = variable.get("causality")
        variability = variable.get("variability")
        if causality not in ("parameter", "input", "output") or \
                variability not in ("fixed", "tunable", "discrete", "continuous"):
            raise ValueError(f"{model}: variable {name} is a {variability} {causality}")
        wire = spec_index.get(name, -1) if causality == "parameter" else -1
        unit = typed.get("unit")
        rows.append(f"    {{{variable.get('valueReference')}u, \"{name}\", {_KINDS[typed.tag]}, "
                    f"SMA_{causality.upper()}, SMA_{variability.upper()}, 0.0, NULL, {wire}, "
                    f"{'NULL' if unit is None else c_string(unit)}}},")
        names.append(f"VAR_{name}")
    lines = [f"/* {model}: its variables, generated by `sma-fmu build --native` from the",
             " * pythonfmu FMU's model description (sma_fmu/fmi/packaging/c_family_description.py).",
             " * Their start values are read from resources/model_starts.json. Do not edit. */",
             f"#ifndef {model.upper()}_VARIABLES_H", f"#define {model.upper()}_VARIABLES_H", "",
             '#include "sma_model.h"', "",
             f'#define MODEL_NAME "{model}"', f'#define MODEL_GUID "{guid}"',
             "#define LOG_CATEGORIES {" + ", ".join(f'"{c}"' for c in LOG_CATEGORIES) + ", NULL}",
             "", "enum { " + ", ".join(names) + ", VAR_COUNT };", "",
             "static const SmaVariable VARIABLES[VAR_COUNT] = {", *rows, "};", "", "#endif", ""]
    return "\n".join(lines)


def model_starts(description, starts, wire_defaults):
    """Text of ``resources/model_starts.json``: the exact start of every variable of the
    native model ``description`` (bytes), and ``wire_defaults`` (the WireParameters of the
    build's parameter file, or None) in PARAMETER_SPECS order, null where Python's is None."""
    root = ET.fromstring(description)
    values = {}
    for variable, typed in _variables(root):
        name = variable.get("name")
        start = starts.get(name)
        if typed.tag == "String":
            values[name] = "" if start is None else str(start)
        elif typed.tag == "Boolean":
            values[name] = bool(start)
        elif typed.tag == "Integer":
            values[name] = int(start or 0)
        else:
            values[name] = float(_number(0.0 if start is None else start))
    wire = [] if wire_defaults is None else \
        [None if getattr(wire_defaults, spec.name) is None else float(_number(getattr(wire_defaults, spec.name)))
         for spec in PARAMETER_SPECS]
    document = {"format": "sma-fmu C-family start values 1", "model": root.get("modelName"),
                "values": values, "wire_defaults": wire}
    return json.dumps(document, indent=1, allow_nan=False) + "\n"
