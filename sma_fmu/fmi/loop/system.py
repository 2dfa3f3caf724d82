"""One scenario's closed loop as a system of FMUs: the one description every master and tool reads.

:func:`loop_system` puts it together once: the components (which FMUs the scenario needs,
:func:`~.wiring.loop_components`), each with its FMU file, its model variables and its
parameter values (the scenario's whole wire as the FMU takes it, :mod:`.wire_values`, then
the scenario's settings, :mod:`.values`), the connections and outputs (:mod:`.wiring`) and
the wire the values come from (its file and digest). The fmpy master
(:mod:`sma_fmu.cosim.master`), the C master, the SSP package and the container FMU
(:mod:`sma_fmu.systems`) all run or write what it says, so they wire and parameterise the
loop alike; :func:`check_variables` says whether the FMUs fit it.
"""
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

from sma_fmu.fmi.driving.description import described
from sma_fmu.fmi.loop.values import component_settings, input_starts, wire_of
from sma_fmu.fmi.loop.wire_values import built_wire, mismatch_error, wire_values
from sma_fmu.fmi.loop.wiring import (COMPONENT_MODELS, STEP_ORDER, loop_components,
                                     loop_connections, loop_outputs)
from sma_fmu.runtime.wire_identity import wire_digest

__all__ = ["MissingFmuError", "Component", "WireSource", "LoopSystem", "loop_system",
           "built_fmus", "check_variables"]


class MissingFmuError(FileNotFoundError):
    """A needed FMU has not been built."""


@dataclass(frozen=True)
class Component:
    """One FMU instance: ``name`` in the system, FMU ``model`` name, its ``fmu`` file,
    ``parameters`` (name -> float, int, bool or str: the start values every host sets), the
    FMU's model ``variables`` (name -> fmpy's ScalarVariable, read once here for everything
    run or written from the system), its ``fmi_version`` ("2" or "3") and ``input_starts``
    (input -> value at t = 0 of the signal feeding it, see :func:`~.values.input_starts`)."""

    name: str
    model: str
    fmu: object
    parameters: dict
    variables: dict
    fmi_version: str = "2"
    input_starts: dict = field(default_factory=dict)


@dataclass(frozen=True)
class WireSource:
    """Where a loop's wire parameter values come from: the ``parameter_file`` (a study may
    change values of it), and ``digest``, the digest of the values themselves
    (:func:`~sma_fmu.runtime.wire_identity.wire_digest`)."""

    parameter_file: object
    digest: str = None

    def record(self):
        """{"file", "digest"}, as a run records its wire."""
        return {"file": None if self.parameter_file is None else str(self.parameter_file),
                "digest": self.digest}


@dataclass(frozen=True)
class LoopSystem:
    """The closed loop of ``scenario``: ``components`` in data-flow order, their
    ``connections``, the ``outputs`` the time series records ({column: (component,
    variable)}), the ``wire`` (the plant's parameters) and the ``model`` (the compensator's
    inverse model: the wire's, unless a study changes it)."""

    scenario: object
    components: tuple
    connections: tuple
    outputs: dict
    wire: WireSource
    model: WireSource

    def component(self, name):
        """The component called ``name``."""
        for component in self.components:
            if component.name == name:
                return component
        raise KeyError(name)

    def in_step_order(self):
        """The components in the Gauss-Seidel order :data:`~.wiring.STEP_ORDER`."""
        return sorted(self.components, key=lambda component: STEP_ORDER.index(component.name))


def built_fmus(fmu_files, models):
    """{model: path} of ``models`` in ``fmu_files`` ({model: path}); :class:`MissingFmuError`
    names the first one not built."""
    for model in models:
        path = Path(fmu_files[model])
        if not path.is_file():
            raise MissingFmuError(f"{fmu_files[model]} not found; build the FMUs first: "
                                  f"sma-fmu build --out {path.parent}")
    return {model: fmu_files[model] for model in models}


def _version(path):
    """(path, size, modification time [ns]): a key that changes when the file does."""
    stat = Path(path).stat()
    return str(Path(path).resolve()), stat.st_size, stat.st_mtime_ns


@lru_cache(maxsize=64)
def _read_fmu(version):
    """({name: ScalarVariable}, FMI major version) of the FMU file ``version`` (:func:`_version`);
    once per file version (a sweep or a bench builds many systems). Only the model description
    is read: whatever unpacks or repacks the archive inspects it first."""
    description = described(version)
    return {v.name: v for v in description.modelVariables}, description.fmiVersion.split(".")[0]


@lru_cache(maxsize=64)
def _built_wire(version):
    """The :class:`~.wire_values.BuiltWire` of the FMU file ``version`` (:func:`_version`)."""
    return built_wire(version[0])


def _component(scenario, name, path, starts, sources, reference_text):
    variables, version = _read_fmu(_version(path))
    wire = wire_of(scenario, name)
    values = {}
    if wire is not None:
        model = COMPONENT_MODELS[name]
        values, refused = wire_values(model, variables, wire, lambda: _built_wire(_version(path)))
        if refused:
            raise mismatch_error(path, model, refused, sources[name].record(),
                                 _built_wire(_version(path)))
    values.update(component_settings(scenario, name, reference_text))
    return Component(name, COMPONENT_MODELS[name], path, values, dict(variables), version,
                     starts.get(name, {}))


def loop_system(scenario, fmu_files, only=None, reference_text=None):
    """The :class:`LoopSystem` of ``scenario`` with the FMU files ``fmu_files`` ({model:
    path}). ``only``: the names of the components to take (default: the whole loop); a
    master that runs the rest of the loop itself (the fmpy master: the PI and the signals)
    gets those components and the connections and outputs among them. ``reference_text``:
    the signals' reference as the caller made it (see :func:`~.values.component_settings`)."""
    feedforward, driver = scenario.controller.feedforward, scenario.drive.driver
    names = [name for name in loop_components(feedforward, driver) if only is None or name in only]
    paths = built_fmus(fmu_files, [COMPONENT_MODELS[name] for name in names])
    connections = loop_connections(feedforward, driver, scenario.drive.limited)
    starts = input_starts(scenario, connections)
    wire = WireSource(scenario.parameter_set.path, wire_digest(scenario.params))
    model = WireSource((scenario.compensator_parameter_set or scenario.parameter_set).path,
                       wire_digest(scenario.compensator_params))
    sources = {"plant": wire, "compensator": model}
    components = tuple(_component(scenario, name, paths[COMPONENT_MODELS[name]], starts, sources,
                                  reference_text)
                       for name in names)
    outputs = {column: source for column, source in loop_outputs(feedforward).items()
               if source[0] in names}
    return LoopSystem(scenario, components,
                      tuple(c for c in connections if c.source in names and c.target in names),
                      outputs, wire, model)


def _need(component, name, causality, types, why):
    variable = component.variables.get(name)
    if variable is None or variable.causality != causality or variable.type not in types:
        found = ("none" if variable is None
                 else f"a {variable.causality} {variable.type}")
        raise ValueError(f"{component.fmu}: the model's variables do not match the loop: "
                         f"{component.name} needs {causality} {name!r} ({'/'.join(types)}; {why}), "
                         f"the FMU has {found}")


def check_variables(system):
    """``ValueError`` naming the FMU and the variable when a component of ``system`` lacks an
    input, output or parameter the loop uses (or has it with another causality or type)."""
    for c in system.connections:
        _need(system.component(c.source), c.output, "output", ("Real",), f"feeds {c.target}.{c.input}")
        _need(system.component(c.target), c.input, "input", ("Real",), f"fed by {c.source}.{c.output}")
    for column, (name, variable) in system.outputs.items():
        types = ("Boolean",) if column == "saturated" else ("Real",)
        _need(system.component(name), variable, "output", types, f"the {column} column")
    for component in system.components:
        for name in component.parameters:
            if name not in component.variables:
                raise ValueError(f"{component.fmu}: the model's variables do not match the loop: "
                                 f"no variable {name!r} for the scenario's value")
