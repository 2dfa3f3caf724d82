"""SSP 1.0 packages of a scenario's closed loop: SystemStructure.ssd + the FMUs under resources/.

The SSD follows what the hosts need (see docs/systems.md and :mod:`.host_needs`):
- the literal prefixes ``ssd:``, ``ssc:``, ``ssv:``, ``oms:`` (libcosim, Ecos and
  OMSimulator match prefixes, not namespaces);
- identifiers as the SSD's and the system's names (OMSimulator refuses others): the
  scenario's name with every other character made "_"; the scenario's own name is in the
  SSD's description;
- a connector, with its type and unit, for every connection end, and no unconnected inputs
  (fmpy's resolver breaks on them);
- one ParameterBinding per component, inline, in a parameter set named :data:`PARAMETER_SET`
  (libcosim applies only the first binding of a component; Ecos applies a set only when
  its name is given to ``init``), of the Real, Integer and Boolean parameters only: a
  String ssv:Parameter makes OMSimulator log an error ("Unknown ParameterBinding-type",
  its ``Values::importStartValuesHelper`` reads only these three), and the packed FMU
  holds every bound value as its default anyway (:data:`BOUND_TYPES`);
- OpenModelica's annotation of the system (``oms:FixedStepMaster`` with the scenario's
  step: without it OMSimulator makes no system) and a DefaultExperiment with start, stop
  and the OSP annotation of the step size (libcosim reads it);
- the FMUs packed with the scenario's values as their defaults (:mod:`.packed`), so a host
  that binds nothing, or no Strings, runs the same scenario.
"""
import io
import zipfile
import xml.etree.ElementTree as ET
from pathlib import Path

from sma_fmu import __version__
from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.fmi.python_family.slave_support.model_description import UNIT_DEFINITIONS
from sma_fmu.fmi.python_family.slave_support.start_values import start_value_text
from sma_fmu.files.output_folder import OutputError, check_folder, staged_folder, write_file
from sma_fmu.systems.closed_loop import closed_loop, identifier
from sma_fmu.systems.packed import packed_fmu

__all__ = ["PARAMETER_SET", "SSD_NAME", "NAMESPACES", "OMS_MASTER", "BOUND_TYPES", "ssd_document",
           "ssp_bytes", "write_ssp", "ssp_targets", "export_ssp"]

PARAMETER_SET = "initial"
SSD_NAME = "SystemStructure.ssd"
NAMESPACES = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
    "osp": "http://opensimulationplatform.com/SSP/OSPAnnotations",
    "oms": "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd",
}
OMS_MASTER = "oms-ma"  # OMSimulator's fixed-step co-simulation master
_OMS_TOLERANCE = "0.0001"  # its tolerances (algebraic loops; the loop here has none)
_FMU_MIME = "application/x-fmu-sharedlibrary"
# the ssv types the SSD binds: those every known host reads (a String is only packed)
BOUND_TYPES = ("Real", "Integer", "Boolean")

for _prefix, _uri in NAMESPACES.items():
    ET.register_namespace(_prefix, _uri)


def _tag(name):
    prefix, local = name.split(":")
    return f"{{{NAMESPACES[prefix]}}}{local}"


def _add(parent, tag, **attributes):
    return ET.SubElement(parent, _tag(tag), {k: v for k, v in attributes.items() if v is not None})


def _connectors(system):
    """{component: {variable: kind}} of every connection end."""
    ends = {}
    for c in system.connections:
        ends.setdefault(c.source, {})[c.output] = "output"
        ends.setdefault(c.target, {})[c.input] = "input"
    return ends


def _component(elements, component, connectors, units):
    variables = component.variables
    node = _add(elements, "ssd:Component", name=component.name, type=_FMU_MIME,
                source=f"resources/{component.model}.fmu")
    if connectors:
        group = _add(node, "ssd:Connectors")
        for name, kind in connectors.items():
            variable = variables[name]
            connector = _add(group, "ssd:Connector", name=name, kind=kind)
            _add(connector, f"ssc:{variable.type}", unit=variable.unit)
            if variable.unit:
                units.add(variable.unit)
    missing = [name for name in component.parameters if name not in variables]
    if missing:
        raise ValueError(f"{component.fmu}: has no variable {missing[0]!r} to bind")
    bound = {name: value for name, value in component.parameters.items()
             if variables[name].type in BOUND_TYPES}   # the rest only as packed defaults
    if bound:
        binding = _add(_add(node, "ssd:ParameterBindings"), "ssd:ParameterBinding")
        values = _add(binding, "ssd:ParameterValues")
        parameters = _add(_add(values, "ssv:ParameterSet", version="1.0", name=PARAMETER_SET),
                          "ssv:Parameters")
        for name, value in bound.items():
            variable = variables[name]
            entry = _add(parameters, "ssv:Parameter", name=name)
            unit = variable.unit if variable.type == "Real" else None
            _add(entry, f"ssv:{variable.type}", value=start_value_text(variable.type, value), unit=unit)
            if unit:
                units.add(unit)


def ssd_document(system):
    """SystemStructure.ssd of ``system`` (a :class:`~sma_fmu.fmi.loop.system.LoopSystem`) as bytes."""
    scenario = system.scenario
    name = identifier(scenario.name)
    root = ET.Element(_tag("ssd:SystemStructureDescription"), version="1.0", name=name,
                      description=f"sma-fmu scenario {scenario.name}",
                      generationTool=f"sma-fmu {__version__}")
    top = _add(root, "ssd:System", name=name, description=scenario.description or None)
    elements = _add(top, "ssd:Elements")
    ends, units = _connectors(system), set()
    for component in system.components:
        _component(elements, component, ends.get(component.name, {}), units)
    connections = _add(top, "ssd:Connections")
    for c in system.connections:
        _add(connections, "ssd:Connection", startElement=c.source, startConnector=c.output,
             endElement=c.target, endConnector=c.input)
    oms = _add(_add(_add(top, "ssd:Annotations"), "ssc:Annotation", type="org.openmodelica"),
               "oms:Annotations")
    _add(_add(oms, "oms:SimulationInformation"), "oms:FixedStepMaster", description=OMS_MASTER,
         stepSize=repr(scenario.step_s), absoluteTolerance=_OMS_TOLERANCE,
         relativeTolerance=_OMS_TOLERANCE)
    unit_group = _add(root, "ssd:Units")
    for name in sorted(units):
        unit = _add(unit_group, "ssc:Unit", name=name)
        _add(unit, "ssc:BaseUnit", **{k: str(v) for k, v in UNIT_DEFINITIONS[name].items()})
    experiment = _add(root, "ssd:DefaultExperiment", startTime="0.0",
                      stopTime=repr(scenario.stop_time_s))
    annotation = _add(_add(experiment, "ssd:Annotations"), "ssc:Annotation",
                      type="com.opensimulationplatform")
    _add(_add(annotation, "osp:Algorithm"), "osp:FixedStepAlgorithm",
         baseStepSize=repr(scenario.step_s))
    ET.indent(root)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)


def ssp_bytes(system):
    """The .ssp archive of ``system``: SystemStructure.ssd at the root, FMUs under resources/,
    each packed with the scenario's values as its defaults (:func:`~.packed.packed_fmu`)."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr(SSD_NAME, ssd_document(system))
        for component in system.components:
            archive.writestr(f"resources/{component.model}.fmu",
                             packed_fmu(component, system.scenario))
    return buffer.getvalue()


def write_ssp(system, path, argument="--out"):
    """Write the .ssp of ``system`` to ``path`` (through a temporary file); returns ``path``."""
    write_file(path, ssp_bytes(system), argument)
    return Path(path)


def ssp_targets(names, out):
    """(folder, {scenario name: .ssp path}): ``out`` is the file for one scenario, else a folder.

    One scenario with ``out`` ending in ``.ssp`` writes that file (``folder`` None);
    otherwise ``out`` is the ``folder`` that gets ``NAME.ssp`` per scenario.
    """
    out = Path(out)
    if out.suffix.lower() == ".ssp":
        if len(names) > 1:
            raise OutputError(f"--out {out}: {len(names)} scenarios need a folder, not one .ssp file")
        return None, {names[0]: out}
    check_folder(out)
    return out, {name: out / f"{name}.ssp" for name in names}


def export_ssp(scenario_paths, out, fmu_dir):
    """Write one .ssp per scenario file (see :func:`ssp_targets`); returns the paths written.

    Every scenario and FMU is checked before anything is written; a failure leaves ``out``
    as it was.
    """
    scenarios = [load_scenario(path) for path in scenario_paths]
    names = [scenario.name for scenario in scenarios]
    repeated = sorted({name for name in names if names.count(name) > 1})
    if repeated:
        raise ValueError(f"two scenario files are both named {repeated[0]!r}; each .ssp is "
                         "named after its scenario")
    folder, targets = ssp_targets(names, out)
    systems = [closed_loop(scenario, fmu_dir) for scenario in scenarios]
    if folder is None:
        return [write_ssp(systems[0], targets[names[0]])]
    with staged_folder(folder) as stage:
        for system, target in zip(systems, targets.values()):
            write_ssp(system, stage / target.name)
    return list(targets.values())
