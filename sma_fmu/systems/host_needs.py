"""What each known SSP host needs from a package, and whether it would run what the SSD binds.

Found by running them on this project's SSPs (docs/systems.md):

- **libcosim** 0.11 (libcosimpy 0.0.6): the step from the OSP annotation
  (``osp:FixedStepAlgorithm baseStepSize``; ``from_ssp_file`` needs it otherwise);
  binds Real, Integer, Boolean and String, from the **first** ParameterBinding of a
  component only.
- **Ecos** 0.7.2 (ecospy): the step from the caller; binds all four types, of the
  parameter set named in ``init(parameter_set=...)``.
- **OMSimulator** 3.0.0: the SSD's, the system's and the components' names must be
  identifiers (``[a-zA-Z][a-zA-Z0-9_]*``: "is not a valid ident", and it stops); the
  system needs OpenModelica's annotation with ``oms:FixedStepMaster`` (else "internal
  error", no system); binds Real, Integer and Boolean, **no String**: its
  ``Values::importStartValuesHelper`` logs an **error line** for any other ssv type
  ("Failed to import ssv:Parameter:Unknown ParameterBinding-type") and goes on with the
  FMU's default; its command line takes the stop time only from ``--stopTime``.
- **fmpy** 0.3.32 ``simulate_ssp``: binds **nothing** and reads neither DefaultExperiment
  nor annotations; every input is 0.0 before the first step (:mod:`.fmpy_ssp`).

A host runs something other than what the SSD binds when it does not apply a binding and
the FMU's default (its packed start value, :mod:`.packed`) differs: :func:`host_check`
fails that host, naming the variable and both values, and likewise a missing annotation,
a name that is no identifier, or a binding that makes the host log an error line (a
String for OMSimulator, even when the FMU's default holds its value: a user who reads
"2 errors" cannot tell that the run is right; :mod:`.ssp` binds no String). fmpy's zero
first inputs give SmaFeedforward R_ref = 0 ohm, which it takes as no reference yet
(P_ff = 0 W, one warning; :mod:`sma_fmu.runtime.feedforward`): the loop runs.
"""
import io
import re
import xml.etree.ElementTree as ET
import zipfile
from dataclasses import dataclass

from sma_fmu.fmi.python_family.slave_support.start_values import parse_start_value
from sma_fmu.systems.packed import fmu_defaults
from sma_fmu.systems.ssp import NAMESPACES, SSD_NAME

__all__ = ["SspHost", "KNOWN_HOSTS", "IDENTIFIER", "UNREAD_BINDING_ERROR", "SspContents", "read_ssp", "host_check",
           "packed_defaults_check"]

IDENTIFIER = re.compile(r"[a-zA-Z][a-zA-Z0-9_]*")
_ALL_TYPES = frozenset(("Real", "Integer", "Boolean", "String"))
# FMUs that take the 0.0 fmpy's simulate_ssp gives every input at the first step as no input yet
_ZERO_AS_UNCONNECTED = {"SmaFeedforward": "R_ref = 0 ohm: P_ff = 0 W until a reference arrives"}
UNREAD_BINDING_ERROR = "Failed to import ssv:Parameter:Unknown ParameterBinding-type"


@dataclass(frozen=True)
class SspHost:
    """What one host needs and applies (see the module docstring)."""

    name: str
    binds: frozenset = _ALL_TYPES      # the ssv types whose bindings it applies
    first_binding_only: bool = False   # only the first ParameterBinding of a component
    identifiers: bool = False          # SSD, system and component names must be identifiers
    annotation: str = None             # "osp" or "oms": where it reads the step
    zero_inputs: bool = False          # every input is 0.0 before the first step
    logs_unread: str = None            # the error line it logs per binding it cannot read
    how: str = ""                      # how it is run (stop time, step, parameter set)


KNOWN_HOSTS = (
    SspHost("libcosim 0.11", first_binding_only=True, annotation="osp",
            how="stopTime is not applied: step it n times"),
    SspHost("Ecos 0.7.2", how="pass step_size and init(parameter_set=\"initial\")"),
    SspHost("OMSimulator 3.0.0", binds=frozenset(("Real", "Integer", "Boolean")), identifiers=True,
            annotation="oms", logs_unread=UNREAD_BINDING_ERROR,
            how="pass --stopTime (its command line ignores the DefaultExperiment)"),
    SspHost("fmpy 0.3.32 simulate_ssp", binds=frozenset(), zero_inputs=True,
            how="pass stop_time and step_size"),
)


@dataclass
class SspContents:
    """What the checks read of an SSP: ``names`` [(what, name)], ``steps`` {"osp"|"oms":
    step [s] or None}, ``stop`` (DefaultExperiment stopTime or None), ``components``
    {name: model name}, ``bindings`` [(component, index of its ParameterBinding, parameter,
    ssv type, value)] and ``defaults`` {component: FmuDefaults}."""

    names: list
    steps: dict
    stop: object
    components: dict
    bindings: list
    defaults: dict


def _tag(name):
    prefix, local = name.split(":")
    return f"{{{NAMESPACES[prefix]}}}{local}"


def _step(node, attribute):
    return None if node is None or node.get(attribute) is None else float(node.get(attribute))


def _binding_parameters(binding, archive):
    """The ssv:Parameter elements of one ParameterBinding (inline, or its .ssv in the SSP)."""
    source = binding.get("source")
    if source:
        root = ET.fromstring(archive.read(source))
        return list(root.iter(_tag("ssv:Parameter")))
    return list(binding.iter(_tag("ssv:Parameter")))


def read_ssp(path):
    """:class:`SspContents` of the SSP file ``path``."""
    with zipfile.ZipFile(path) as archive:
        root = ET.fromstring(archive.read(SSD_NAME))
        system = root.find(_tag("ssd:System"))
        names = [("SSD name", root.get("name", "")), ("system name", system.get("name", ""))]
        components, bindings, defaults = {}, [], {}
        for component in system.iter(_tag("ssd:Component")):
            name = component.get("name", "")
            names.append(("component name", name))
            with zipfile.ZipFile(io.BytesIO(archive.read(component.get("source")))) as fmu:
                defaults[name] = fmu_defaults(fmu)
            components[name] = defaults[name].model
            for index, binding in enumerate(component.iter(_tag("ssd:ParameterBinding"))):
                for parameter in _binding_parameters(binding, archive):
                    value = parameter[0]
                    kind = value.tag.rsplit("}", 1)[-1]
                    bindings.append((name, index, parameter.get("name"), kind, value.get("value")))
        experiment = root.find(_tag("ssd:DefaultExperiment"))
    steps = {"osp": _step(root.find(f".//{_tag('osp:FixedStepAlgorithm')}"), "baseStepSize"),
             "oms": _step(system.find(f"{_tag('ssd:Annotations')}//{_tag('oms:FixedStepMaster')}"),
                          "stepSize")}
    stop = _step(experiment, "stopTime")
    return SspContents(names, steps, stop, components, bindings, defaults)


def _differs(contents, component, parameter, kind, text):
    """(default, bound value) when the FMU's default differs from the bound value, else None."""
    defaults = contents.defaults[component]
    if parameter not in defaults.starts:
        return "(no such parameter)", text
    bound = parse_start_value(kind, text)
    default = defaults.value(parameter)
    return None if default == bound else (default, bound)


def host_check(host, contents):
    """(status, detail) of ``host`` (an :class:`SspHost`) on an SSP's :class:`SspContents`."""
    problems, notes = [], []
    if host.identifiers:
        problems += [f"{what} {name!r} is not an identifier (it stops: 'is not a valid ident')"
                     for what, name in contents.names if not IDENTIFIER.fullmatch(name)]
        notes.append("the SSD's, the system's and the components' names are identifiers")
    if host.annotation:
        step = contents.steps[host.annotation]
        where = {"osp": "osp:FixedStepAlgorithm baseStepSize",
                 "oms": "org.openmodelica annotation oms:FixedStepMaster"}[host.annotation]
        if step is None:
            problems.append(f"no {where}: it has no step size"
                            + (" and makes no system" if host.annotation == "oms" else ""))
        else:
            notes.append(f"step {step!r} s from the {where}")
    others = {s for key, s in contents.steps.items() if s is not None}
    if len(others) > 1:
        problems.append(f"the annotations give different steps: {sorted(others)}")
    skipped, unread = [], []
    for component, index, parameter, kind, text in contents.bindings:
        applied = kind in host.binds and not (host.first_binding_only and index > 0)
        if applied:
            continue
        skipped.append(f"{component}.{parameter}")
        if host.logs_unread and kind not in host.binds:
            unread.append(f"{component}.{parameter} (ssv:{kind})")
        differs = _differs(contents, component, parameter, kind, text)
        if differs:
            why = (f"it binds no {kind}" if kind not in host.binds
                   else "it applies only the first ParameterBinding of a component")
            problems.append(f"{component}.{parameter} would be {differs[0]!r} (the FMU's default), "
                            f"not the bound {differs[1]!r}: {why}")
    bound = len(contents.bindings) - len(skipped)
    if skipped and not bound:
        notes.append(f"binds none of the {len(skipped)} values: all from the FMUs' defaults")
    elif skipped:
        notes.append(f"binds {bound} of {len(contents.bindings)} values; "
                     f"{', '.join(skipped) if len(skipped) <= 4 else f'{len(skipped)} others'} "
                     "from the FMUs' defaults")
    else:
        notes.append(f"binds all {bound} values")
    if host.how:
        notes.append(host.how)
    errors = ([f"would log {len(unread)} error line(s) {host.logs_unread!r}, one per binding "
               f"of a type it cannot read: {', '.join(unread)}"] if unread else [])
    if problems or errors:
        return "FAIL", "; ".join(errors + ([f"would not run what the SSD binds: "
                                            f"{'; '.join(problems)}"] if problems else []))
    if host.zero_inputs:
        unconnected = [f"{name}: {_ZERO_AS_UNCONNECTED[model]}"
                       for name, model in contents.components.items() if model in _ZERO_AS_UNCONNECTED]
        notes.append("its first step gets 0.0 on every input, not the outputs after "
                     "initialization" + (f" ({'; '.join(unconnected)})" if unconnected else ""))
    return "ok", "; ".join(notes)


def packed_defaults_check(contents):
    """(status, detail): do the FMUs' packed defaults agree with their model descriptions and
    with the SSD's bindings (``contents``: :class:`SspContents`)? "n/a" when no FMU carries
    packed defaults."""
    packed = [name for name, defaults in contents.defaults.items() if defaults.packed]
    if not packed:
        return "n/a", "no FMU carries packed defaults (resources/start_values.json)"
    problems = [f"{name}: {problem}" for name in packed
                for problem in contents.defaults[name].problems()]
    for component, _, parameter, kind, text in contents.bindings:
        differs = _differs(contents, component, parameter, kind, text)
        if differs:
            problems.append(f"{component}.{parameter}: bound {differs[1]!r}, the FMU's default "
                            f"{differs[0]!r}")
    if problems:
        return "FAIL", "; ".join(problems)
    return "ok", (f"{len(packed)} FMUs carry the bound values as their defaults "
                  f"({len(contents.bindings)} values)")
