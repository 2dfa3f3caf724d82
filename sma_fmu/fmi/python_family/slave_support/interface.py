"""Shared plumbing of the FMU slave classes (``fmi/python_family/slaves/``): variables with units, parameters, guards.

It imports pythonfmu: it runs only inside an FMU (or while one is built), and every
pythonfmu FMU ships pythonfmu in its resources/. The library path never imports it.

The build writes the wire's parameter set to ``resources/parameters.json``; a slave
exposes the wire parameters its model uses as FMI parameters (:mod:`.wire_use`: start
values from that file, NaN for an optional one the file does not give) and takes the rest
from the file as they are. Every slave states the digest of that wire
(:mod:`sma_fmu.runtime.wire_identity`) in the String constant ``wire_digest``. An FMU
packed by ``sma-fmu export`` also has ``resources/start_values.json``
(:mod:`.start_values`): the scenario's values, which replace the start values of the
parameters it names. Settings that choose among names
are Integer parameters holding a code (:mod:`.choices`).

Creating a :class:`SlaveInterface` also puts a :class:`~.guards.CallGuard` over the
slave's pythonfmu callbacks: the FMI state machine, checked arguments and saved states,
and no exception ever reaching pythonfmu (which would make it fmi2Fatal).
"""
import json
import math
import os

from pythonfmu import Boolean, Fmi2Causality, Fmi2Initial, Fmi2Variability, Integer, Real, String
from pythonfmu.enums import Fmi2Status

from sma_fmu.fmi.python_family.slave_support.choices import choice_code, choice_text
from sma_fmu.fmi.python_family.slave_support.guards import CallGuard
from sma_fmu.fmi.python_family.slave_support.lifecycle import setting_refusal
from sma_fmu.fmi.python_family.slave_support.model_description import decorate_model_description
from sma_fmu.fmi.python_family.slave_support.saved_state import state_from_bytes, state_to_bytes
from sma_fmu.fmi.python_family.slave_support.start_values import START_VALUES_FILE, read_start_values, start_value
from sma_fmu.fmi.python_family.slave_support.wire_use import (NULLABLE, WIRE_DIGEST, not_given_text,
                                                               wire_names)
from sma_fmu.runtime.parameters import SPEC_BY_NAME, WireParameters
from sma_fmu.runtime.wire_identity import wire_digest
from sma_fmu.runtime.scenario_signals import GRID_TOLERANCE

__all__ = ["PARAMETERS_FILE", "SlaveInterface"]

PARAMETERS_FILE = "parameters.json"
_KIND_OF = ((Real, "Real"), (Boolean, "Boolean"), (String, "String"), (Integer, "Integer"))


class SlaveInterface:
    """Declares one slave's variables (with units and descriptions) and guards its steps."""

    def __init__(self, slave):
        self.slave = slave
        self.units = {}
        self.exposed = []
        # value reference -> (name, kind, causality, variability); table lookups replace
        # pythonfmu's generic accessors (they run at every step)
        self._variables = {}
        self._tables = {}
        self.guard = CallGuard(slave, self)
        # pythonfmu calls the state byte conversions on the class: make them never raise
        cls = type(slave)
        cls._fmu_state_to_bytes = staticmethod(state_to_bytes)
        cls._fmu_state_from_bytes = staticmethod(state_from_bytes)
        with open(os.path.join(slave.resources, PARAMETERS_FILE), encoding="utf-8") as stream:
            self.parameter_file = json.load(stream)
        entries = self.parameter_file["parameters"]
        self.defaults = WireParameters.from_values(
            {name: entry["value"] for name, entry in entries.items()},
            source=self.parameter_file.get("source", PARAMETERS_FILE))
        self.digest = wire_digest(self.defaults)   # of the values themselves, not of a claim
        self.nullable = set()   # the exposed wire parameters that may be NaN: not given
        # the scenario's values packed at export: they replace the parameters' start values
        self.packed = read_start_values(slave.resources)
        self.first_step = None  # h0 [s]: the size of the first step (see nominal_step)

    def _declare(self, variable, start, unit):
        kind = next(name for cls, name in _KIND_OF if isinstance(variable, cls))
        if variable.causality is Fmi2Causality.parameter and variable.name in self.packed:
            start = start_value(kind, self.packed[variable.name],
                                f"{START_VALUES_FILE}: {variable.name}")
        setattr(self.slave, variable.name, start)
        self.slave.register_variable(variable)
        self._variables[variable.value_reference] = (
            variable.name, kind, variable.causality.name, variable.variability.name)
        self._tables.clear()
        if unit is not None:
            self.units[variable.name] = unit

    # ---- variable tables (used by the guard) ----------------------------------------------
    def _table(self, key, build):
        table = self._tables.get(key)
        if table is None:
            table = self._tables[key] = build()
        return table

    def names(self, kind):
        """{value reference: attribute name} of the variables of type ``kind`` ("Real", ...)."""
        return self._table(kind, lambda: {vr: v[0] for vr, v in self._variables.items() if v[1] == kind})

    def settable(self, kind, state):
        """{value reference: name} of the ``kind`` variables that may be set in ``state``."""
        return self._table((kind, state), lambda: {
            vr: v[0] for vr, v in self._variables.items()
            if v[1] == kind and setting_refusal(v[2], v[3], state) is None})

    def setting_refusal(self, kind, reference, state):
        """Why value reference ``reference`` cannot be set as a ``kind`` in ``state``."""
        variable = self._variables.get(reference)
        if variable is None or variable[1] != kind:
            return self.describe_reference(kind, reference)
        return f"{variable[0]} (value reference {reference}) cannot be set: " \
               f"{setting_refusal(variable[2], variable[3], state)}"

    def describe_reference(self, kind, reference):
        """Text for a value reference that is not a variable of type ``kind``.

        ``reference`` as pythonfmu passes it (a signed int); the text names it as the host did.
        """
        reference &= 0xFFFFFFFF  # fmi2ValueReference is unsigned
        variable = self._variables.get(reference)
        if variable is None:
            return f"value reference {reference} is not a variable of {self.slave.modelName}"
        return f"value reference {reference} is {variable[1]} variable {variable[0]}, not a {kind}"

    def variable_kinds(self):
        """{name: kind} of every variable (what a saved state must hold)."""
        return {v[0]: v[1] for v in self._variables.values()}

    def real_output_names(self):
        """Names of the Real outputs (which must stay finite)."""
        return [v[0] for v in self._variables.values() if v[1] == "Real" and v[2] == "output"]

    def log(self, message, status=Fmi2Status.ok):
        """Log ``message`` for the host, naming the model and instance.

        Every '%' is doubled: a host that uses the message as a printf format (pythonfmu
        passes it so, when no front is built) prints it literally; the front undoes it.
        """
        text = f"{self.slave.modelName} '{self.slave.instance_name}': {message}"
        self.slave.log(text.replace("%", "%%"), status)

    def parameter(self, name, start, unit, description, kind=Real):
        """A fixed parameter ``name`` with ``start`` value, ``unit`` and ``description``."""
        self._declare(kind(name, causality=Fmi2Causality.parameter,
                           variability=Fmi2Variability.fixed, description=description),
                      start, unit)

    def model_parameters(self, names=None):
        """Expose the wire parameters ``names`` (default: those the model uses,
        :func:`~.wire_use.wire_names`) as fixed parameters, in PARAMETER_SPECS order; an
        optional one the file does not give starts at NaN, "not given"."""
        entries = self.parameter_file["parameters"]
        wanted = set(wire_names(self.slave.modelName) if names is None else names)
        for spec in (spec for name, spec in SPEC_BY_NAME.items() if name in wanted):
            start = getattr(self.defaults, spec.name)
            meaning = entries.get(spec.name, {}).get("meaning") or (
                "optional, not in the parameter file" if start is None else spec.name)
            if spec.rule == "depth":  # a count: an Integer (FMI 2.0 Integers have no unit)
                self.parameter(spec.name, int(start), None, f"{meaning} [{spec.section}, 1]",
                               kind=Integer)
            else:
                if spec.name in NULLABLE:
                    self.nullable.add(spec.name)
                    meaning += f"; {not_given_text(spec.name)}"
                self.parameter(spec.name, math.nan if start is None else start, spec.unit,
                               f"{meaning} [{spec.section}]")
            self.exposed.append(spec.name)

    def state_wire_digest(self):
        """The String constant ``wire_digest``: the digest of the wire the FMU was built
        from (declared after the slave's own variables, :class:`~.stepper_slave.StepperSlave`)."""
        self._declare(String(WIRE_DIGEST, causality=Fmi2Causality.local,
                             variability=Fmi2Variability.constant, initial=Fmi2Initial.exact,
                             start=self.digest,
                             description="SHA-256 of the canonical values of the wire parameter "
                                         "file the FMU was built from (resources/parameters.json)"),
                      self.digest, None)

    def string_parameter(self, name, start, description):
        """A fixed String parameter (no unit)."""
        self.parameter(name, start, None, description, kind=String)

    def choice_parameter(self, name, start, description):
        """A fixed Integer parameter choosing among the names of :data:`~.choices.CHOICES`
        [``name``]; ``start`` is a name, the description ends with the codes."""
        code = choice_code(name, start)
        self.parameter(name, code, None, f"{description} ({choice_text(name)})", kind=Integer)

    def boolean_parameter(self, name, start, description):
        """A fixed Boolean parameter."""
        self.parameter(name, start, None, description, kind=Boolean)

    def input(self, name, start, unit, description):
        """A continuous Real input."""
        self._declare(Real(name, causality=Fmi2Causality.input,
                           variability=Fmi2Variability.continuous, description=description),
                      start, unit)

    def output(self, name, unit, description):
        """A continuous Real output computed at initialization and at every step."""
        self._declare(Real(name, causality=Fmi2Causality.output,
                           variability=Fmi2Variability.continuous,
                           initial=Fmi2Initial.calculated, description=description),
                      0.0, unit)

    def boolean_output(self, name, description):
        """A discrete Boolean output computed at initialization and at every step."""
        self._declare(Boolean(name, causality=Fmi2Causality.output,
                              variability=Fmi2Variability.discrete,
                              initial=Fmi2Initial.calculated, description=description),
                      False, None)

    def nominal_step(self, step_size):
        """h0, the first step's size [s], when ``step_size`` [s] is within GRID_TOLERANCE
        steps of it, else ``step_size``: a host that steps from t to t_next passes
        t_next - t, a few rounding errors off h (OMSimulator), and the slave then steps by
        the h the library loop uses (docs/systems.md, the time grid)."""
        first = self.first_step
        if first is None:
            self.first_step = first = step_size
        return first if abs(step_size - first) <= GRID_TOLERANCE * first else step_size

    def wire_parameters(self):
        """WireParameters from the file, with the exposed parameters' present values (NaN in
        an optional one: not given)."""
        values = self.defaults.values()
        for name in self.exposed:
            value = getattr(self.slave, name)
            if name in self.nullable and value != value:  # NaN
                values.pop(name, None)
            else:
                values[name] = value
        return WireParameters.from_values(
            values, source=f"{self.slave.modelName} instance '{self.slave.instance_name}'")

    def decorate(self, root):
        """Add units, output dependencies, InitialUnknowns and exact Real starts to
        pythonfmu's description."""
        starts = {v.name: v.start for v in self.slave.vars.values()
                  if isinstance(v, Real) and v.start is not None}
        return decorate_model_description(root, self.units, starts)
