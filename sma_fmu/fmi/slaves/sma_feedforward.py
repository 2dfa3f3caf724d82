"""SmaFeedforward: the feedforward hysteresis compensator as an FMI 2.0 CS FMU.

A thin adapter over ``sma_fmu.runtime.feedforward.FeedforwardStepper``: the
temperature-sensing inverse of the wire model followed by the phase-lag filter.

Semantics: a sampled block. doStep(t_k, h) samples R_ref and load as set before the
call and its outputs then hold u_ff,k for that step; step it before the plant
(Gauss-Seidel) so u_ff,k reaches the plant's step k without delay. After
initialization the outputs are those of the first sample (filter in steady state); in
Initialization Mode they follow R_ref, load and the parameters as they are set.
Invalid parameters are logged as fmi2Error at exitInitializationMode; the outputs are
then NaN and every doStep is discarded.
"""
from pythonfmu import Fmi2Slave
from pythonfmu.default_experiment import DefaultExperiment

from sma_fmu.runtime.constant_load import branch_constants
from sma_fmu.runtime.constants import HEATING
from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.fmi.slave_support.interface import SlaveInterface

INVALID_OUTPUTS = (float("nan"), float("nan"), False)


def _mid_transformation_resistance(params):
    """Resistance [ohm] half way through the heating transformation at the model load."""
    constants = branch_constants(params.model_load, HEATING, params)
    return (params.R_P + constants.xi_F_min * (params.R_F - params.R_P)
            + 0.5 * constants.M * (params.R_MF - params.R_P))


class SmaFeedforward(Fmi2Slave):

    author = "sma-fmu"
    description = "SMA feedforward compensator: temperature-sensing inverse model + phase-lag filter"
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=30.0, step_size=1e-3)

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
        fmi.string_parameter("inverse", "major",
                             "'major' (the paper's: major branches) or 'minor-loop' (the plant's "
                             "continuous-mode minor branches, reversals taken from R_ref)")
        fmi.model_parameters(extra=("alpha", "beta", "model_load", "saturation_margin"))
        self.stepper = None
        self._publish(FeedforwardStepper(fmi.defaults).initial_outputs(self.R_ref, self.load))
        fmi.preview_outputs(self._start, self._publish, INVALID_OUTPUTS)

    def _start(self):
        stepper = FeedforwardStepper(self.interface.wire_parameters(),
                                     adapt_to_load=self.adapt_to_load, inverse=self.inverse)
        return stepper, stepper.initial_outputs(self.R_ref, self.load)

    def _publish(self, outputs):
        self.P_ff, self.T_ref, self.saturated = outputs

    def exit_initialization_mode(self):
        self.stepper, outputs = self.interface.initialize(self._start, INVALID_OUTPUTS)
        self._publish(outputs)

    def do_step(self, current_time, step_size):
        if self.stepper is None:
            return self.interface.not_initialized(current_time)
        try:
            self._publish(self.stepper.step(self.R_ref, self.load, step_size))
        except Exception as error:  # an exception here would reach the host as fmi2Fatal
            return self.interface.report(f"step at t = {current_time!r} s discarded", error)
        return True

    def to_xml(self, model_options=dict()):
        return self.interface.decorate(super().to_xml(model_options))

    def _get_fmu_state(self):
        return self.interface.state_with(super()._get_fmu_state(), self.stepper)

    def _set_fmu_state(self, state):
        variables, stepper_state = self.interface.split_state(state)
        super()._set_fmu_state(variables)
        # a new stepper with the restored parameters, then its hidden state
        self.stepper = None if stepper_state is None else self._start()[0]
        if self.stepper is not None:
            self.stepper.restore(stepper_state)
