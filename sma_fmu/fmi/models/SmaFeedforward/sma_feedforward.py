"""SmaFeedforward: the feedforward hysteresis compensator as an FMI 2.0 CS FMU.

A thin adapter over ``sma_fmu.runtime.feedforward.FeedforwardStepper``: the
temperature-sensing inverse of the wire model followed by the phase-lag filter.

Semantics: a sampled block. doStep(t_k, h) samples R_ref and load as set before the
call and its outputs then hold u_ff,k for that step; step it before the plant
(Gauss-Seidel) so u_ff,k reaches the plant's step k without delay. After
initialization the outputs are those of the first sample (filter in steady state); in
Initialization Mode they follow R_ref, load and the parameters as they are set.
Invalid parameters make exitInitializationMode fail with fmi2Error naming the reason;
the instance stays in Initialization Mode, where they can be corrected. ``inverse`` is an
Integer: 1 = major, 2 = minor-loop; ``shaping`` too: 1 = none (the phase-lag filter),
2 = reachable (``slave_support/choices.py``), with ``power_cap`` [W] the driver's P_max
(0: no limit) and ``anticipation`` [s] the lead at the reference's lower turn (0: none). A step within a millionth of the first step's size is taken as that size
(the time grid, docs/systems.md).
"""
from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.reachable_band import reachable_band
from sma_fmu.fmi.python_family.slave_support.choices import choice_name
from sma_fmu.fmi.python_family.slave_support.interface import SlaveInterface
from sma_fmu.fmi.python_family.slave_support.stepper_slave import StepperSlave


def power_cap_of(value):
    """The runtime's power_cap [W] of the FMU parameter: 0 means no limit (None)."""
    return None if value == 0.0 else value


def _mid_transformation_resistance(params):
    """Resistance [ohm] half way through the transformation at the model load: mid-band."""
    band = reachable_band(params.model_load, params)
    return 0.5 * (band.hot + band.cold)


class SmaFeedforward(StepperSlave):

    description = "SMA feedforward compensator: temperature-sensing inverse model + phase-lag filter"

    published = ("P_ff", "T_ref", "saturated")
    step_inputs = ("R_ref", "load")  # stepper.step(..., step_size)

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.interface = fmi = SlaveInterface(self)
        fmi.input("R_ref", _mid_transformation_resistance(fmi.defaults), "ohm",
                  "reference resistance (> 0)")
        fmi.input("load", 0.0, "kg", "measured hung mass (>= 0); used when adapt_to_load")
        fmi.output("P_ff", "W", "feedforward power u_ff (may be < 0; clamp the loop's sum at 0 W)")
        fmi.output("T_ref", "degC", "temperature the inverse model assigns to R_ref")
        fmi.boolean_output("saturated", "true when R_ref is outside the transformation (T_ref clamped)")
        fmi.boolean_parameter("adapt_to_load", True,
                              "true: the inverse uses the measured load; false: model_load")
        fmi.choice_parameter("inverse", "major",
                             "major: the paper's, major branches; minor-loop: the plant's "
                             "continuous-mode minor branches, reversals taken from R_ref")
        fmi.model_parameters()
        fmi.choice_parameter("shaping", "none",
                             "none: the paper's, T_ref through the phase-lag filter; reachable: "
                             "the demand shaped into what the wire can reach, over a model of it")
        fmi.parameter("power_cap", 0.0, "W", "with shaping reachable: the most power the "
                      "driver delivers, P_max (0: no limit)")
        fmi.parameter("anticipation", 0.0, "s", "with shaping reachable: aim this far ahead "
                      "near the reference's lower turn, from its past samples (0: none)")
        self.stepper = None

    def _start(self):
        stepper = FeedforwardStepper(self.interface.wire_parameters(),
                                     adapt_to_load=self.adapt_to_load,
                                     inverse=choice_name("inverse", self.inverse),
                                     shaping=choice_name("shaping", self.shaping),
                                     power_cap=power_cap_of(self.power_cap),
                                     anticipation=self.anticipation)
        return stepper, stepper.initial_outputs(self.R_ref, self.load)
