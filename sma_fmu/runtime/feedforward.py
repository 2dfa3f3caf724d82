"""Stateful feedforward compensator: temperature-sensing inverse + phase-lag filter (spec section 10).

    R_ref, f -> T_ref = sense(R_ref, f, d_ref) -> v = (T_ref - T_room)/K_th -> u_ff = Cpl(s) v

d_ref comes from successive reference samples: a falling R_ref means heating (+1), a
rising one cooling (-1), an equal one keeps the last; the first sample is heating.
The inverse always uses the major branches, as the paper's compensator does. With
``adapt_to_load`` the measured load enters the inverse; otherwise the fixed ``model_load``.
"""
from collections import namedtuple

from .checks import fast_nonnegative, fast_positive, require_nonnegative, require_positive
from .constant_load import BranchCache
from .constants import COOLING, HEATING
from .phase_lag import PhaseLagFilter
from .sensing import mixed_fractions_of_resistance, temperature_of_fractions

__all__ = ["FeedforwardOutputs", "FeedforwardStepper"]

FeedforwardOutputs = namedtuple("FeedforwardOutputs", ["P_ff", "T_ref", "saturated"])
_new_tuple = tuple.__new__  # builds the namedtuple in C (see plant.py)
FeedforwardOutputs.__doc__ = """Compensator outputs for one reference sample.

P_ff : feedforward power u_ff [W] (may be negative; the loop clamps the sum at 0 W);
T_ref : temperature the inverse model assigns to R_ref [degC];
saturated : True when R_ref lies outside the transformation (T_ref is clamped).
"""


class FeedforwardStepper:
    """Feedforward hysteresis compensator for one wire.

    Parameters
    ----------
    params : WireParameters
    alpha, beta : float, optional
        Phase-lag lead and lag times [s]; default from ``params`` (alpha = tau_th).
    model_load : float, optional
        Load assumed by the inverse when not adapting [kg]; default from ``params``.
    adapt_to_load : bool
        True: the inverse uses the measured load ("adaptive"); False: ``model_load``.
    """

    def __init__(self, params, alpha=None, beta=None, model_load=None, adapt_to_load=True):
        self.params = params
        self.filter = PhaseLagFilter(
            params.phase_lag_alpha if alpha is None else alpha,
            params.beta if beta is None else beta)
        self.model_load = require_nonnegative(
            "model_load", params.model_load if model_load is None else model_load)
        self.adapt_to_load = bool(adapt_to_load)
        self.direction = HEATING
        self.previous_reference = None
        self._branches = BranchCache(params)

    def _invert(self, reference, load, direction):
        params = self.params
        constants = self._branches.get(load if self.adapt_to_load else self.model_load, direction)
        xi_mf, xi_p = mixed_fractions_of_resistance(reference, constants, params)
        sensed = temperature_of_fractions(xi_mf, xi_p, constants, params.saturation_margin)
        return sensed, (sensed.temperature - params.T_room) / params.K_th

    def _direction_for(self, reference):
        previous = self.previous_reference
        if previous is None or reference == previous:
            return self.direction
        return HEATING if reference < previous else COOLING

    def initial_outputs(self, reference, load):
        """Outputs before the first step (filter in steady state); the state is unchanged.

        ``reference`` R_ref [ohm], ``load`` [kg].
        """
        if self.filter.previous_input is not None:
            raise RuntimeError("initial_outputs is only defined before the first step")
        reference = require_positive("R_ref", reference)
        load = require_nonnegative("load", load)
        sensed, power = self._invert(reference, load, self._direction_for(reference))
        return FeedforwardOutputs(power, sensed.temperature, sensed.saturated)

    def step(self, reference, load, step_size):
        """Compensate one sample: R_ref [ohm] and load [kg] at t_k, step h [s] -> outputs.

        Invalid inputs raise ``ValueError`` before any state changes.
        """
        reference = fast_positive("R_ref", reference)
        load = fast_nonnegative("load", load)
        step_size = fast_positive("step_size", step_size)
        direction = self._direction_for(reference)
        sensed, power = self._invert(reference, load, direction)
        output = self.filter.step(power, step_size)
        self.direction = direction
        self.previous_reference = reference
        return _new_tuple(FeedforwardOutputs, (output, sensed.temperature, sensed.saturated))

    def state(self):
        """JSON-ready hidden state (reference direction, last reference, filter memory)."""
        return {"direction": self.direction, "previous_reference": self.previous_reference,
                "filter": self.filter.state()}

    def restore(self, state):
        """Restore a state saved by :meth:`state`."""
        self.direction = state["direction"]
        self.previous_reference = state["previous_reference"]
        self.filter.restore(state["filter"])
