"""The FMI 3.0 model description and build description of a C-family FMU, from its FMI 2.0 one.

Nothing about the interface is written twice: the FMI 3.0 description is the native FMI 2.0
one (:mod:`.c_family_description`) in FMI 3.0's terms:

- ``instantiationToken`` for the ``guid``; ``CoSimulation`` with saved and serialized
  states and event mode; the models with events of their own (``events`` in their
  declaration, :mod:`sma_fmu.fmi.models`: the PWM driver's edges, the signals' load and
  set-point steps) may return early from a step, at the event;
- the independent variable ``time`` [s], one value reference past the model's variables (the
  C core keeps the FMI 2.0 numbering);
- Real -> Float64 (its unit kept), Integer -> Int32, Boolean, String (start as ``<Start>``),
  and the choice parameters (``hysteresis_mode``, ``inverse``) -> Enumerations of their
  named items;
- the plant's reversal stack as Float64 array outputs sized by the structural parameter
  ``memory_depth`` (:mod:`.array_outputs`), value references past ``time``;
- ModelStructure by value reference; no ``<SourceFiles>``: ``sources/buildDescription.xml``
  lists the files (:func:`build_description`).

:func:`fmi3_model_header` writes ``fmi3_model.h``: what the FMI 3.0 front needs to know of
the model beyond the core's table (the value reference of ``time``, the Enumerations, the
structural parameter and the arrays).
"""
import xml.etree.ElementTree as ET

from sma_fmu.fmi.models import declaration
from sma_fmu.fmi.packaging.cross_build import RUNS_HERE, TARGETS
from sma_fmu.fmi.packaging.array_outputs import ARRAYS
from sma_fmu.fmi.python_family.slave_support.choices import CHOICES

__all__ = ["fmi3_description", "platforms_document", "build_description",
           "fmi3_model_header", "time_reference"]

_CO_SIMULATION = {"canHandleVariableCommunicationStepSize": "true",
                  "canGetAndSetFMUState": "true", "canSerializeFMUState": "true",
                  "hasEventMode": "true", "providesIntermediateUpdate": "false",
                  "canReturnEarlyAfterIntermediateUpdate": "false"}
_TYPES = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean", "String": "String"}
_KEPT = ("name", "valueReference", "description", "causality", "variability", "initial")


def time_reference(root):
    """The value reference of ``time``: one past the largest of the model's variables."""
    return max(int(v.get("valueReference")) for v in root.find("ModelVariables")) + 1


def _variable(scalar, typed, parent, arrays=None):
    """The FMI 3.0 element of one FMI 2.0 ScalarVariable (and its type element); the
    ``arrays``' size parameter becomes a UInt64 structural parameter within its bounds."""
    name = scalar.get("name")
    kind = "Enumeration" if typed.tag == "Integer" and name in CHOICES else _TYPES[typed.tag]
    structural = arrays is not None and name == arrays.size
    if structural:
        kind = "UInt64"
    element = ET.SubElement(parent, kind, {k: scalar.get(k) for k in _KEPT if scalar.get(k)})
    if structural:
        element.set("causality", "structuralParameter")
        element.set("min", str(arrays.minimum))
        element.set("max", str(arrays.maximum))
    if kind == "Enumeration":
        element.set("declaredType", f"{name}_type")
    for key, value in typed.attrib.items():
        if kind == "String" and key == "start":
            ET.SubElement(element, "Start", value=value)
        elif key in ("start", "unit", "displayUnit", "min", "max", "nominal", "quantity"):
            if not (structural and key in ("min", "max")):
                element.set(key, value)
    return element


def _array_variables(arrays, size_reference, first, parent):
    """The arrays' Float64 outputs (one ``<Dimension>`` each, the size parameter's value
    reference) and their UInt64 count, from value reference ``first`` on; their references."""
    references = []
    for offset, (name, unit, text) in enumerate(arrays.arrays):
        reference = str(first + offset)
        element = ET.SubElement(parent, "Float64", name=name, valueReference=reference,
                                description=text, causality="output", variability="discrete",
                                unit=unit)
        ET.SubElement(element, "Dimension", valueReference=size_reference)
        references.append(reference)
    name, text = arrays.count
    reference = str(first + len(arrays.arrays))
    ET.SubElement(parent, "UInt64", name=name, valueReference=reference, description=text,
                  causality="output", variability="discrete")
    return references + [reference]


def fmi3_description(fmi2_description):
    """The FMI 3.0 model description (bytes) of the native FMI 2.0 one (bytes)."""
    old = ET.fromstring(fmi2_description)
    root = ET.Element("fmiModelDescription", fmiVersion="3.0")
    for key in ("modelName", "description", "author", "version", "generationTool",
                "generationDateAndTime", "variableNamingConvention"):
        if old.get(key):
            root.set(key, old.get(key))
    root.set("instantiationToken", old.get("guid"))
    identifier = old.find("CoSimulation").get("modelIdentifier")
    co_simulation = ET.SubElement(root, "CoSimulation", modelIdentifier=identifier, **_CO_SIMULATION)
    if declaration(old.get("modelName")).events:
        co_simulation.set("mightReturnEarlyFromDoStep", "true")
    if old.find("UnitDefinitions") is not None:
        units = ET.SubElement(root, "UnitDefinitions")
        units.extend(old.find("UnitDefinitions"))
        if not any(u.get("name") == "s" for u in units):
            ET.SubElement(ET.SubElement(units, "Unit", name="s"), "BaseUnit", s="1")
    variables = old.find("ModelVariables")
    names = [v.get("name") for v in variables]
    choices = [n for n in CHOICES if n in names]
    if choices:
        types = ET.SubElement(root, "TypeDefinitions")
        for name in choices:
            enumeration = ET.SubElement(types, "EnumerationType", name=f"{name}_type")
            for code, item in CHOICES[name].items():
                ET.SubElement(enumeration, "Item", name=item, value=str(code))
    categories = ET.SubElement(root, "LogCategories")
    for category in old.find("LogCategories"):
        text = (category.get("description") or "").replace("fmi2", "fmi3")
        ET.SubElement(categories, "Category", name=category.get("name"), description=text)
    if old.find("DefaultExperiment") is not None:
        root.append(old.find("DefaultExperiment"))
    model_variables = ET.SubElement(root, "ModelVariables")
    ET.SubElement(model_variables, "Float64", name="time", valueReference=str(time_reference(old)),
                  causality="independent", variability="continuous",
                  description="simulation time", unit="s")
    arrays = ARRAYS.get(old.get("modelName"))
    for scalar in variables:
        typed = next(child for child in scalar if child.tag in _TYPES)
        _variable(scalar, typed, model_variables, arrays)
    added = []
    if arrays is not None:
        size = next(v.get("valueReference") for v in variables if v.get("name") == arrays.size)
        added = _array_variables(arrays, size, time_reference(old) + 1, model_variables)
    structure = ET.SubElement(root, "ModelStructure")
    references = [v.get("valueReference") for v in variables]
    for group, tag in (("Outputs", "Output"), ("InitialUnknowns", "InitialUnknown")):
        found = old.find("ModelStructure").find(group)
        for unknown in found if found is not None else ():
            ET.SubElement(structure, tag, valueReference=references[int(unknown.get("index")) - 1])
        for reference in added:
            ET.SubElement(structure, tag, valueReference=reference)
    ET.indent(root, "\t")
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True) + b"\n"


def platforms_document(binaries):
    """The FMU's platforms.PLATFORMS_FILE (bytes; ``sma-fmu check`` reads it) naming the
    native ``binaries`` ({platform tuple: path in the FMU}), attributes as in FMI 2.0."""
    root = ET.Element("Platforms", tool="sma-fmu")
    for name, binary in binaries.items():
        ET.SubElement(root, "Platform", name=name, binary=binary, front="false",
                      python="none (native C)", native="true",
                      tested=RUNS_HERE[TARGETS[name].runs])  # as the FMI 2.0 annotation says
    ET.indent(root, "\t")
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True) + b"\n"


def build_description(model_identifier, source_files):
    """``sources/buildDescription.xml`` (bytes): the C99 files a tool compiles."""
    root = ET.Element("fmiBuildDescription", fmiVersion="3.0")
    configuration = ET.SubElement(root, "BuildConfiguration", modelIdentifier=model_identifier)
    files = ET.SubElement(configuration, "SourceFileSet", language="C99",
                          compilerOptions="-ffp-contract=off")
    for name in source_files:
        ET.SubElement(files, "SourceFile", name=name)
    ET.indent(root, "\t")
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True) + b"\n"


def fmi3_model_header(fmi3_description_bytes):
    """Text of ``fmi3_model.h``: the value references of ``time``, the Enumerations, the
    structural parameter, the arrays and their count (``time`` standing for none), all macros."""
    root = ET.fromstring(fmi3_description_bytes)
    variables = root.find("ModelVariables")
    time = next(v for v in variables if v.get("causality") == "independent").get("valueReference")
    enumerations = [v.get("valueReference") + "u" for v in variables if v.tag == "Enumeration"]
    arrays = ARRAYS.get(root.get("modelName"))
    by_name = {v.get("name"): v.get("valueReference") for v in variables}
    if arrays is None:
        structural, bounds, count, count_name = time, (1, 1), time, "time"
        array_vrs, array_names = [time + "u"], ['"time"']
    else:
        structural, bounds = by_name[arrays.size], (arrays.minimum, arrays.maximum)
        count, count_name = by_name[arrays.count[0]], arrays.count[0]
        array_vrs = [by_name[name] + "u" for name, _, _ in arrays.arrays]
        array_names = [f'"{name}"' for name, _, _ in arrays.arrays]
    return "\n".join([
        f"/* {root.get('modelName')}: what the FMI 3.0 front knows of it beyond the core's table,",
        " * generated by `sma-fmu build --native --fmi 3` (sma_fmu/fmi/packaging/fmi3_description.py).",
        " * Do not edit. */",
        "#ifndef SMA_FMI3_MODEL_H", "#define SMA_FMI3_MODEL_H", "",
        f"#define TIME_VR {time}u  /* the independent variable time [s] */",
        "/* the Enumerations (read and set as Int64); time stands for none */",
        f"#define ENUMERATIONS {{{', '.join(enumerations or [time + 'u'])}}}",
        "/* the UInt64 structural parameter sizing the arrays, its bounds, the UInt64 output",
        " * counting their live entries, the Float64 arrays in the model's order (array_outputs.py);",
        " * time stands for none */",
        f"#define STRUCTURAL_VR {structural}u",
        f"#define STRUCTURAL_MIN {bounds[0]}u", f"#define STRUCTURAL_MAX {bounds[1]}u",
        f"#define COUNT_VR {count}u", f'#define COUNT_NAME "{count_name}"',
        f"#define ARRAY_VRS {{{', '.join(array_vrs)}}}",
        f"#define ARRAY_NAMES {{{', '.join(array_names)}}}", "", "#endif", ""])
