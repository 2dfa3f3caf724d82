"""SmaPiController: the loop's PI block (anti-windup, power clamp at 0 W) as an FMI 2.0 CS FMU.

A thin adapter over ``sma_fmu.runtime.measurement.SensedPIController``: the PI block of the
library loop (``sma_fmu.runtime.pi_control.PIController``) fed through the controller's
resistance sensor (``ResistanceSensor``: white noise of ``noise_ohm_rms`` from stream
``seed``, then a ``bits``-bit ADC over 0 ... ``full_scale_ohm``; all 0 by
default: R read exactly). R is the wire's true resistance; the PI's error is
e = R_measured - R_ref, and ``R_measured`` shows the reading of the step. Sample k of the
noise is the k-th doStep.

Semantics: a sampled block, like SmaFeedforward. doStep(t_k, h) samples R, R_ref and P_ff
as set before the call; its outputs then hold u_k = max(0, P_ff + Kp e_k + Ki I_k) with
e_k = R - R_ref for that step, and the integrator advances. Before the first step (also
in Initialization Mode) the outputs are those the first step will give: the present
inputs with I = 0. Non-finite inputs discard the step. Invalid gains make
exitInitializationMode fail with fmi2Error naming the reason; the instance stays in
Initialization Mode, where they can be corrected. A step within a millionth of the first
step's size is taken as that size (the time grid, docs/systems.md).
"""
from sma_fmu.fmi.python_family.slave_support.interface import SlaveInterface
from sma_fmu.fmi.python_family.slave_support.stepper_slave import StepperSlave
from pythonfmu import Integer

from sma_fmu.runtime.measurement import ResistanceSensor, SensedPIController


class SmaPiController(StepperSlave):

    description = "PI resistance controller of the SMA wire: anti-windup, power clamped at 0 W"

    published = ("P", "P_fb", "R_measured")
    step_inputs = ("R", "R_ref", "P_ff")  # stepper.sample(..., step_size)
    step_method = "sample"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.interface = fmi = SlaveInterface(self)
        defaults = fmi.defaults
        fmi.input("R", defaults.R_P, "ohm", "the wire's resistance, read through the sensor")
        fmi.input("R_ref", defaults.R_P, "ohm", "reference resistance; error e = R_measured - R_ref")
        fmi.input("P_ff", 0.0, "W", "feedforward power u_ff (0 W without a compensator)")
        fmi.output("P", "W", "power command u = max(0, P_ff + Kp e + Ki I) for this step")
        fmi.output("P_fb", "W", "feedback part Kp e + Ki I (before the clamp)")
        fmi.model_parameters(("Kp", "Ki"))
        fmi.output("R_measured", "ohm",
                   "the resistance the PI read this step: R through the sensor's noise and ADC")
        fmi.parameter("noise_ohm_rms", 0.0, "ohm",
                      "sensor noise referred to R (>= 0; an Irwin-Hall normal stream)")
        fmi.parameter("full_scale_ohm", 0.0, "ohm",
                      "the ADC's range 0 ... full scale in resistance (> 0 when bits > 0)")
        fmi.parameter("bits", 0, None, "the ADC's resolution, 0-32 (0: no quantisation)",
                      kind=Integer)
        fmi.parameter("seed", 0, None, "the noise stream, 0 ... 2^31 - 1 (SplitMix64)",
                      kind=Integer)
        self.stepper = None

    def _start(self):
        params = self.interface.wire_parameters()
        sensor = ResistanceSensor(self.noise_ohm_rms, self.full_scale_ohm, self.bits,
                                  self.seed)
        stepper = SensedPIController(params.Kp, params.Ki, sensor)
        return stepper, stepper.preview(self.R, self.R_ref, self.P_ff)
