"""Shared plumbing of the FMU slave classes (``fmi/slaves/``): variables with units, parameters, guards.

It imports pythonfmu: it runs only inside an FMU (or while one is built), and every
pythonfmu FMU ships pythonfmu in its resources/. The library path never imports it.

The build writes the wire's parameter set to ``resources/parameters.json``; a slave
exposes some of those parameters as FMI parameters (start values from that file) and
takes the rest from the file as they are.
"""
import json
import os

from pythonfmu import Boolean, Fmi2Causality, Fmi2Initial, Fmi2Variability, Real, String
from pythonfmu.enums import Fmi2Status

from sma_fmu.fmi.slave_support.model_description import decorate_model_description
from sma_fmu.runtime.parameters import PARAMETER_SPECS, WireParameters

__all__ = ["PARAMETERS_FILE", "MODEL_SECTIONS", "SlaveInterface"]

PARAMETERS_FILE = "parameters.json"
MODEL_SECTIONS = ("geometry", "phases", "hysteresis", "constant_load", "thermal")
_STATE_KEY = "__stepper__"


class SlaveInterface:
    """Declares one slave's variables (with units and descriptions) and guards its steps."""

    def __init__(self, slave):
        self.slave = slave
        self.units = {}
        self.exposed = []
        self.initialization_error = None
        self._preview = None  # recomputes the outputs until exitInitializationMode
        self._reals = {}     # value reference -> attribute name, Real variables
        self._booleans = {}  # value reference -> attribute name, Boolean variables
        # pythonfmu's generic accessors check every variable's type on every call; these
        # table lookups do the same job in about half the time (they run at every step)
        slave.get_real, slave.set_real, slave.get_boolean = (
            self._get_real, self._set_real, self._get_boolean)
        with open(os.path.join(slave.resources, PARAMETERS_FILE), encoding="utf-8") as stream:
            self.parameter_file = json.load(stream)
        entries = self.parameter_file["parameters"]
        self.defaults = WireParameters.from_values(
            {name: entry["value"] for name, entry in entries.items()},
            source=self.parameter_file.get("source", PARAMETERS_FILE))

    def _declare(self, variable, start, unit):
        setattr(self.slave, variable.name, start)
        self.slave.register_variable(variable)
        if isinstance(variable, Real):
            self._reals[variable.value_reference] = variable.name
        elif isinstance(variable, Boolean):
            self._booleans[variable.value_reference] = variable.name
        if unit is not None:
            self.units[variable.name] = unit

    def _get_real(self, references):
        if self._preview is not None:
            self._preview()
        slave, names = self.slave, self._reals
        return [float(getattr(slave, names[vr])) for vr in references]

    def _set_real(self, references, values):
        slave, names = self.slave, self._reals
        for vr, value in zip(references, values):
            setattr(slave, names[vr], value)

    def _get_boolean(self, references):
        if self._preview is not None:
            self._preview()
        slave, names = self.slave, self._booleans
        return [bool(getattr(slave, names[vr])) for vr in references]

    def parameter(self, name, start, unit, description, kind=Real):
        """A fixed parameter ``name`` with ``start`` value, ``unit`` and ``description``."""
        self._declare(kind(name, causality=Fmi2Causality.parameter,
                           variability=Fmi2Variability.fixed, description=description),
                      start, unit)

    def model_parameters(self, sections=MODEL_SECTIONS, extra=()):
        """Expose the wire parameters of ``sections`` (plus names in ``extra``) as parameters."""
        entries = self.parameter_file["parameters"]
        for spec in PARAMETER_SPECS:
            if spec.section in sections or spec.name in extra:
                entry = entries.get(spec.name, {})
                start = getattr(self.defaults, "phase_lag_alpha" if spec.name == "alpha" else spec.name)
                meaning = entry.get("meaning") or (
                    "phase-lag lead time (default: thermal time constant)" if spec.name == "alpha" else spec.name)
                self.parameter(spec.name, start, spec.unit, f"{meaning} [{spec.section}]")
                self.exposed.append(spec.name)

    def string_parameter(self, name, start, description):
        """A fixed String parameter (no unit)."""
        self.parameter(name, start, None, description, kind=String)

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

    def wire_parameters(self):
        """WireParameters from the file, with the exposed parameters' present values."""
        values = self.defaults.values()
        for name in self.exposed:
            values[name] = getattr(self.slave, name)
        return WireParameters.from_values(
            values, source=f"{self.slave.modelName} instance '{self.slave.instance_name}'")

    def decorate(self, root):
        """Add units, output dependencies and InitialUnknowns to pythonfmu's description."""
        return decorate_model_description(root, self.units)

    def preview_outputs(self, start, publish, invalid_outputs):
        """Until exitInitializationMode, compute the outputs afresh whenever they are read.

        Hosts read outputs in Initialization Mode (libcosim and Ecos do, to pass start values
        along connections), so they must follow the inputs and parameters set so far:
        ``publish(start()[1])``, or ``publish(invalid_outputs)`` while ``start`` raises (the
        error is logged at exitInitializationMode).
        """
        def preview():
            try:
                outputs = start()[1]
            except Exception:  # noqa: BLE001 - reported by initialize()
                outputs = invalid_outputs
            publish(outputs)
        self._preview = preview

    def initialize(self, start, invalid_outputs):
        """Run ``start()`` -> (stepper, outputs) at exitInitializationMode; never raise.

        pythonfmu turns an exception here into fmi2Fatal, after which a host may not even
        free the instance. Invalid parameters are instead logged as fmi2Error, the outputs
        become ``invalid_outputs`` (NaN) and every doStep is discarded with the reason.
        """
        self._preview = None
        try:
            stepper, outputs = start()
        except ValueError as error:
            self.initialization_error = str(error)
            self.report("initialization failed (every doStep will be discarded)", error)
            return None, invalid_outputs
        self.initialization_error = None
        return stepper, outputs

    def not_initialized(self, current_time):
        """Discard a doStep of an instance without a valid initialization; returns False."""
        reason = self.initialization_error or "exitInitializationMode was not called"
        return self.report(f"step at t = {current_time!r} s discarded", f"not initialized: {reason}")

    def report(self, where, error):
        """Log ``error`` as an fmi2Error message naming the instance and ``where``; return False.

        The FMU then answers fmi2Discard instead of letting an exception become fmi2Fatal.
        """
        self.slave.log(f"{self.slave.modelName} '{self.slave.instance_name}' {where}: {error}",
                       Fmi2Status.error)
        return False

    @staticmethod
    def state_with(state, stepper):
        """Add a stepper's hidden state to pythonfmu's variable state (JSON-ready)."""
        state[_STATE_KEY] = None if stepper is None else stepper.state()
        return state

    @staticmethod
    def split_state(state):
        """(variable state, stepper state) of a state made by :meth:`state_with`."""
        variables = dict(state)
        return variables, variables.pop(_STATE_KEY, None)
