"""FMUs packed with a scenario's parameter values as their defaults (for SSP packages and containers).

A host that binds no parameter (fmpy's ``simulate_ssp``) or not every type (OMSimulator
binds no Strings) runs each FMU with its defaults. So ``sma-fmu export`` packs every
component's FMU with the scenario's values as the defaults, in the two places that hold
them:

- ``modelDescription.xml``: the ``start`` attribute of each bound parameter, and a
  DefaultExperiment with the scenario's stop time and step;
- ``resources/start_values.json``: the same values, which the slave reads when it is
  instantiated (:mod:`sma_fmu.fmi.python_family.slave_support.start_values`).

The bindings of the SSP and the container's start values hold the same values, so every
host runs the scenario whatever it binds. :func:`fmu_defaults` reads both places back
(``sma-fmu check`` compares them with the bindings).
"""
import io
import json
import math
import zipfile
import xml.etree.ElementTree as ET

from sma_fmu import __version__
from sma_fmu.files.archives import require_safe_archive
from sma_fmu.fmi.python_family.slave_support.start_values import (START_VALUES_FILE, parse_start_value,
                                                    start_value, start_value_text)

__all__ = ["MODEL_DESCRIPTION", "START_VALUES_ENTRY", "FmuDefaults", "packed_fmu", "fmu_defaults"]

MODEL_DESCRIPTION = "modelDescription.xml"
START_VALUES_ENTRY = f"resources/{START_VALUES_FILE}"
_TYPES = ("Real", "Integer", "Boolean", "String", "Enumeration")


def _typed(variable):
    """(type element, its FMI type) of a ScalarVariable element (an Enumeration's is Integer)."""
    for child in variable:
        if child.tag in _TYPES:
            return child, "Integer" if child.tag == "Enumeration" else child.tag
    raise ValueError(f"variable {variable.get('name')!r} has no type element")


def _set_starts(root, values, label):
    """Set the start attribute of the parameters in ``values``; returns {name: JSON value}."""
    variables = {v.get("name"): v for v in root.find("ModelVariables")}
    packed = {}
    for name, value in values.items():
        variable = variables.get(name)
        if variable is None or variable.get("causality") != "parameter":
            raise ValueError(f"{label}: has no parameter {name!r}")
        element, kind = _typed(variable)
        if kind == "Real" and isinstance(value, float) and math.isnan(value):
            raise ValueError(
                f"{label}: the scenario's wire does not give {name}, which the FMU was built "
                f"with (start {element.get('start')}): an export packs no \"not given\" (NaN) "
                f"for hosts to bind; build the FMUs from the scenario's parameter file "
                f"(sma-fmu build --model FILE) and export again")
        value = start_value(kind, value, f"{label}: {name}")
        element.set("start", start_value_text(kind, value))
        packed[name] = value
    return packed


def _set_experiment(root, scenario):
    experiment = root.find("DefaultExperiment")
    if experiment is None:
        experiment = ET.Element("DefaultExperiment")
        root.insert(list(root).index(root.find("ModelVariables")), experiment)
    experiment.attrib.clear()
    experiment.set("startTime", "0.0")
    experiment.set("stopTime", repr(float(scenario.stop_time_s)))
    experiment.set("stepSize", repr(float(scenario.step_s)))


def packed_fmu(component, scenario):
    """The bytes of ``component``'s FMU with its parameter values as defaults (see the module);
    its archive is inspected first (an export packs it for hosts that unpack it)."""
    label = f"{component.name} ({component.model}.fmu)"
    require_safe_archive(component.fmu)
    buffer = io.BytesIO()
    with zipfile.ZipFile(component.fmu) as source, \
            zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as target:
        names = source.namelist()
        if MODEL_DESCRIPTION not in names:
            raise ValueError(f"{component.fmu}: no {MODEL_DESCRIPTION}")
        for item in source.infolist():
            if item.filename == START_VALUES_ENTRY:
                continue  # packed before: replaced below
            data = source.read(item.filename)
            if item.filename == MODEL_DESCRIPTION:
                root = ET.fromstring(data)
                packed = _set_starts(root, component.parameters, label)
                _set_experiment(root, scenario)
                data = ET.tostring(root, encoding="UTF-8", xml_declaration=True)
            target.writestr(item, data)
        document = {"source": f"sma-fmu {__version__} export: scenario {scenario.name}, "
                              f"component {component.name}",
                    "values": packed}
        target.writestr(START_VALUES_ENTRY, json.dumps(document, indent=1, allow_nan=False))
    return buffer.getvalue()


class FmuDefaults:
    """The defaults an FMU carries: ``starts`` {parameter: (FMI type, start value)} from its
    modelDescription.xml, ``packed`` {name: value} from its start_values.json ({} if none) and
    ``model`` its modelName."""

    def __init__(self, starts, packed, model=None):
        self.starts = starts
        self.packed = packed
        self.model = model

    def problems(self):
        """Texts naming each packed value that is not a parameter or differs from its start."""
        found = []
        for name, value in self.packed.items():
            if name not in self.starts:
                found.append(f"{START_VALUES_FILE} names {name!r}, which is no parameter")
                continue
            kind, start = self.starts[name]
            try:
                value = start_value(kind, value, name)
            except ValueError as error:
                found.append(f"{START_VALUES_FILE}: {error}")
                continue
            if value != start:
                found.append(f"{START_VALUES_FILE} has {name} = {value!r}, modelDescription.xml "
                             f"start = {start!r}")
        return found

    def value(self, name):
        """The value the FMU runs with when ``name`` is not set: the packed value, else the start."""
        kind, start = self.starts[name]
        return start_value(kind, self.packed[name], name) if name in self.packed else start


def fmu_defaults(archive):
    """:class:`FmuDefaults` of an FMU (a path or an open :class:`zipfile.ZipFile`)."""
    if not isinstance(archive, zipfile.ZipFile):
        with zipfile.ZipFile(archive) as opened:
            return fmu_defaults(opened)
    root = ET.fromstring(archive.read(MODEL_DESCRIPTION))
    starts = {}
    for variable in root.find("ModelVariables"):
        if variable.get("causality") == "parameter":
            element, kind = _typed(variable)
            if element.get("start") is not None:
                starts[variable.get("name")] = (kind, parse_start_value(kind, element.get("start")))
    packed = {}
    if START_VALUES_ENTRY in archive.namelist():
        document = json.loads(archive.read(START_VALUES_ENTRY))
        packed = document.get("values", {}) if isinstance(document, dict) else {}
    return FmuDefaults(starts, packed, root.get("modelName"))
