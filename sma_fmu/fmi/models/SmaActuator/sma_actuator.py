"""SmaActuator: the SMA wire plant (thermal model + resistance hysteresis) as an FMI 2.0 CS FMU.

A thin adapter over ``sma_fmu.runtime.plant.PlantStepper``. At build time ``sma_fmu.runtime``
is renamed to a version-stamped package shipped in resources/, so FMUs of different
versions loaded into one process never share a module.

Semantics: doStep(t, h) holds P_in and load over the step (P_in <= 0 is applied as 0 W);
the outputs are then the state at t + h with the held load (no direct feedthrough). After initialization the
outputs reflect T_start and the load set during initialization (in Initialization Mode
they follow them as they are set). Invalid parameters make exitInitializationMode
fail with fmi2Error naming the reason; the instance stays in Initialization Mode, where
they can be corrected (see the guard, ``slave_support/guards.py``). ``hysteresis_mode`` is
an Integer: 1 = continuous, 2 = switch (``slave_support/choices.py``). A step within a
millionth of the first step's size is taken as that size (the time grid, docs/systems.md).
"""
from sma_fmu.fmi.python_family.slave_support.choices import choice_name
from sma_fmu.fmi.python_family.slave_support.interface import SlaveInterface
from sma_fmu.fmi.python_family.slave_support.stepper_slave import StepperSlave
from sma_fmu.runtime.plant import PlantStepper

OUTPUTS = (
    ("R", "ohm", "wire resistance"),
    ("T", "degC", "wire temperature"),
    ("x", "m", "wire length"),
    ("xi_P", "1", "P-phase (austenite) fraction"),
    ("xi_M", "1", "M-phase (twinned martensite) fraction"),
    ("xi_F", "1", "F-phase (detwinned martensite) fraction"),
    ("P", "W", "power applied to the wire over the last step: max(0, P_in)"),
)


class SmaActuator(StepperSlave):

    description = "SMA wire actuator: Joule heating, first-order thermal model, resistance hysteresis under load"

    published = ("R", "T", "x", "xi_P", "xi_M", "xi_F", "P", "heating")
    step_inputs = ("P_in", "load")  # stepper.step(..., step_size)

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.interface = fmi = SlaveInterface(self)
        fmi.input("P_in", 0.0, "W", "electric power I^2 R into the wire; <= 0 is applied as 0 W")
        fmi.input("load", 0.0, "kg", "hung mass on the wire (>= 0); force = g * load")
        for name, unit, text in OUTPUTS:
            fmi.output(name, unit, text)
        fmi.boolean_output("heating", "true while dT/dt > 0 (the last sign is kept when dT/dt = 0)")
        fmi.parameter("T_start", fmi.defaults.T_room, "degC", "initial wire temperature")
        fmi.choice_parameter("hysteresis_mode", "continuous",
                             "continuous: minor loops, holds a set-point; switch: the paper's, "
                             "branch follows sgn dT/dt, limit-cycles at a set-point")
        fmi.model_parameters()
        self.stepper = None

    def _start(self):
        stepper = PlantStepper(self.interface.wire_parameters(), self.T_start,
                               choice_name("hysteresis_mode", self.hysteresis_mode), self.load)
        return stepper, stepper.outputs
