"""SmaScenarioSignals: a scenario's reference R_ref(t) and load f(t) as an FMI 2.0 CS FMU.

A thin adapter over ``sma_fmu.runtime.scenario_signals.SignalSource``, which evaluates the
signals of ``sma_fmu.runtime.signals``, the code that scenario files use.

Parameters: ``reference`` and ``load_profile``, String parameters holding a scenario's
``[reference]`` and ``[load]`` tables as JSON objects (FMI 2.0 has no arrays); their
defaults, from ``resources/signals.json``, are the paper's load-step scenario, and in an
FMU packed by ``sma-fmu export`` the exported scenario's (``resources/start_values.json``),
so a host that binds no String runs that scenario.
Semantics: a source. After initialization the outputs are the signals at the start
time; after doStep(t, h) they are the signals at t + h, taken on the step's grid
start + k h when t + h is within a millionth of a step of it (a host that adds up its
time samples where the library loop does). Invalid tables make
exitInitializationMode fail with fmi2Error naming the parameter and the key; the
instance stays in Initialization Mode, where they can be corrected.
"""
import json
import os

from sma_fmu.fmi.python_family.slave_support.interface import SlaveInterface
from sma_fmu.fmi.python_family.slave_support.stepper_slave import StepperSlave
from sma_fmu.runtime.scenario_signals import SignalSource, signals_from_text, table_text

DEFAULTS_FILE = "signals.json"


class SmaScenarioSignals(StepperSlave):

    description = "Scenario signals of the SMA wire loop: reference resistance R_ref(t) and load f(t)"
    snaps_step = False   # puts its time on the step grid itself (see the module docstring)

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.interface = fmi = SlaveInterface(self)
        with open(os.path.join(self.resources, DEFAULTS_FILE), encoding="utf-8") as stream:
            defaults = json.load(stream)
        fmi.output("R_ref", "ohm", "reference resistance R_ref(t) at the communication point")
        fmi.output("load", "kg", "hung mass f(t) at the communication point")
        fmi.string_parameter(
            "reference", table_text(defaults["reference"]),
            "R_ref(t): a scenario's [reference] table as a JSON object, e.g. "
            '{"kind":"constant","value_ohm":40.0}; kinds constant, step, ramp, sine, cosine, table')
        fmi.string_parameter(
            "load_profile", table_text(defaults["load"]),
            "piecewise-constant load: a scenario's [load] table as a JSON object, "
            '{"times_s":[0.0,...],"values_kg":[...]}; values_kg[i] from times_s[i] on')
        self.start_time = 0.0
        self.stepper = None

    def _start(self):
        reference, load = signals_from_text(self.reference, self.load_profile)
        stepper = SignalSource(reference, load, self.start_time)
        return stepper, stepper.outputs

    def _publish(self, outputs):
        self.R_ref, self.load = outputs

    def setup_experiment(self, start_time, stop_time, tolerance):
        self.start_time = start_time

    def _advance(self, current_time, step_size):
        # the grid's h0 is the run's first step (the interface's, as the native adapter's
        # SmaRun.first_step): a source restored from a saved state would otherwise take the
        # next step's size, which a host that steps from t to t_next passes a rounding error
        # off h0, and sample off the saved run's grid
        interface = self.interface
        if interface.first_step is None:
            interface.first_step = step_size
        self.stepper.grid_step = interface.first_step
        return self.stepper.step(current_time, step_size)
