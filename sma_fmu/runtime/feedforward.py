"""Stateful feedforward compensator: temperature-sensing inverse + phase-lag filter (spec section 10).

    R_ref, f -> T_ref = inverse(R_ref, f, d_ref) -> v = (T_ref - T_room)/K_th -> u_ff = Cpl(s) v

d_ref comes from successive reference samples: a falling R_ref means heating (+1), a
rising one cooling (-1), an equal one keeps the last; the first sample is heating.
With ``adapt_to_load`` the measured load enters the inverse; otherwise the fixed ``model_load``.

Two inverses (``inverse``):

- ``"major"`` (default, the paper's): the major branch of d_ref (section 5).
- ``"minor-loop"``: the branch the plant's continuous mode (section 6) is on. The
  compensator keeps its own stack of reversal points with the plant's rules: when d_ref
  changes at sample k, it pushes the state it assumed at sample k-1, (T_ref,k-1,
  xi_MF,k-1), where xi_MF,k-1 is the fraction of R_ref(t_k-1) at the load then (or, where
  that sample was clamped, the fraction of its branch at the clamped T_ref,k-1). The
  branch of the stack is inverted in closed form, walking the stack: a target beyond the
  branch's end B lies on the outer branch, and the loop it closes is wiped out
  (:func:`~.sensing.temperature_on_stack`). After a load change the branches are
  re-evaluated with the new load, as the plant does. With an empty stack it is the major
  branch of d_ref; it starts heating, as the plant does.

In both, a reference outside what the branch can reach at the present load gives the
temperature of the nearest reachable edge (xi_MF clamped to delta or M - delta of the
section 5 clamp) and ``saturated`` = True.

Shaping (``shaping``): ``"none"`` (default, the paper's) turns T_ref into power through the
phase-lag filter; ``"reachable"`` shapes the demand into what the wire can reach in a step
(heating up to ``power_cap``, cooling no faster than convection) over a model of the wire
whose memory is the plant's, and outputs the thermal model's exact one-step power
(:mod:`.shaping`; the filter is not used). The inverse is then taken on the model's branch.
Shaped, ``anticipation`` L > 0 [s] aims the shaping L ahead of the reference near its lower
turn, from its past samples (:mod:`.anticipation`); 0 (default): R_ref itself.

No reference yet: R_ref <= 0 ohm before the first R_ref > 0 (a host that steps before its
inputs are connected, as fmpy's ``simulate_ssp`` gives every input 0.0 at t = 0) is an
unconnected start, not an error. That step outputs P_ff = 0 W, T_ref = T_room and
``saturated`` = True, sets one warning (the first such step only) and changes no state:
the first R_ref > 0 is the compensator's first sample (filter started in steady state).
After a reference has arrived, R_ref <= 0 is refused (``ValueError``) as before.

**choice** (the demand beyond validity): the compensator never demands a temperature above
``validity.T_max``. Where the inverse gives more (a load far above the validity limit
makes the transformation, and so the inverse, climb to thousands of degC), T_ref is
bounded to T_max, P_ff is the steady-state power of T_max, ``saturated`` is True, and the
first step of each such excursion sets a warning. The inverse's own memory (the minor-loop
stack) keeps the unbounded temperature, as the plant's branch would.

A wire that gives the range its data covered (``validity.T_data_min`` ...): the first step
whose T_ref or load lies outside it sets one more warning, once in the stepper's life (as
the plant does).
"""
import math
from collections import namedtuple

from .anticipation import TurnAnticipation
from .checks import fast_nonnegative, fast_positive, require_nonnegative, require_positive
from .constant_load import BranchCache
from .constants import COOLING, HEATING
from .minor_loops import push_reversal, read_points
from .phase_lag import PhaseLagFilter
from .sensing import (invert_on_stack, mixed_fractions_of_resistance, temperature_of_fractions,
                      temperature_with_tangent)
from .shaping import ReachableShaping, require_power_cap, require_shaping
from .state_entries import (StateError, check_format, read_direction, read_entries,
                            read_optional_number, read_temperature, require_pair)
from .validity import data_box, data_range_warning, validity_warning

__all__ = ["INVERSES", "require_inverse", "FeedforwardOutputs", "FeedforwardStepper",
           "STATE_FORMAT"]

STATE_FORMAT = "sma-fmu compensator state 3: reversal stack, search tangent"   # state() writes it
_STATE_ENTRIES = ("format", "direction", "previous_reference", "reversals",
                  "previous_temperature", "previous_fraction", "previous_exponent",
                  "previous_slope", "filter")

INVERSES = ("major", "minor-loop")

FeedforwardOutputs = namedtuple("FeedforwardOutputs", ["P_ff", "T_ref", "saturated"])
_new_tuple = tuple.__new__  # builds the namedtuple in C (see plant.py)
FeedforwardOutputs.__doc__ = """Compensator outputs for one reference sample.

P_ff : feedforward power u_ff [W] (may be negative; the loop clamps the sum at 0 W);
T_ref : temperature the inverse model assigns to R_ref [degC];
saturated : True when R_ref is outside what the inverted branch reaches at the present
load (T_ref is then the temperature of the nearest reachable edge); shaped, also when the
model wire does not reach the inverse's temperature in the step.
"""


def _anticipation(lead, shaping):
    """The :class:`TurnAnticipation` of ``lead`` L [s] (None for 0); L > 0 needs shaping
    "reachable" (the paper's filter has no model to aim with)."""
    lead = require_nonnegative("anticipation", lead)
    if lead == 0.0:
        return None
    if shaping != "reachable":
        raise ValueError(f"anticipation = {lead!r} s needs shaping 'reachable', got {shaping!r}")
    return TurnAnticipation(lead)


def require_inverse(inverse):
    """Return ``inverse`` if it is one of :data:`INVERSES`, else raise ``ValueError``."""
    if isinstance(inverse, str) and inverse in INVERSES:
        return inverse
    raise ValueError(f"inverse must be one of {', '.join(INVERSES)}, got {inverse!r}")


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
    inverse : "major" | "minor-loop"
        Invert the major branches (the paper's) or the minor branches of the plant's
        continuous mode, with a stack of reversals taken from d_ref (see the module docstring).
    shaping : "none" | "reachable"
        The paper's phase-lag filter, or the demand shaped into what the wire can reach
        (:mod:`.shaping`).
    power_cap : float, optional
        P_max [W] the driver can deliver, with shaping "reachable"; None: no limit.
    anticipation : float
        L [s] >= 0, with shaping "reachable": aim L ahead near the reference's lower turn
        (:mod:`.anticipation`); 0: no anticipation.
    """

    def __init__(self, params, alpha=None, beta=None, model_load=None, adapt_to_load=True,
                 inverse="major", shaping="none", power_cap=None, anticipation=0.0):
        self.params = params
        self.filter = PhaseLagFilter(
            params.phase_lag_alpha if alpha is None else alpha,
            params.beta if beta is None else beta)
        self.model_load = require_nonnegative(
            "model_load", params.model_load if model_load is None else model_load)
        self.adapt_to_load = bool(adapt_to_load)
        self.inverse = require_inverse(inverse)
        self._minor_loops = self.inverse == "minor-loop"
        self.shaping = require_shaping(shaping)
        self.power_cap = require_power_cap(power_cap, self.shaping)
        self._shaper = (ReachableShaping(params, self._minor_loops, self.power_cap,
                                         self.model_load) if self.shaping == "reachable" else None)
        self._anticipation = _anticipation(anticipation, self.shaping)
        self.direction = HEATING
        self.previous_reference = None
        self.reversals = []               # minor-loop memory: ReversalPoint(T [degC], xi_MF [1])
        self.previous_temperature = None  # T_ref,k-1 [degC] (minor-loop inverse only)
        self.previous_fraction = None     # xi_MF,k-1 [1] the compensator assumed
        self.previous_line = None         # (Lambda [1], -Lambda' [K]) at T_ref,k-1 (two stages)
        self._branches = BranchCache(params)
        self.warning = None               # validity warning of the last step (the load)
        self._load_before = -math.inf     # load of the last step [kg]
        self._unconnected_warned = False  # the no-reference-yet warning was given
        self._bounded_before = False      # the last step's T_ref was bounded to T_max
        self._data_unwarned = params.data_range   # the data-range warning is still to come
        self._data_box = data_box(params)    # its bounds, missing ones infinite

    def _invert(self, reference, load, direction):
        """(SensedTemperature, stack, xi_MF assumed, tangent line) for one sample; no state
        change.

        The memory is the compensator's (the last d_ref, T_ref and xi_MF, its stack, the
        two-stage search's tangent there) or, shaped, the model wire's (its direction,
        temperature, xi_MF and stack; no tangent: the model's temperature is not the last
        root). The stack returned is that list itself when it is unchanged, else a copy; the
        line is the major inverse's (``temperature_with_tangent``), None for the minor loop.
        """
        params = self.params
        constants = self._branches.get(load if self.adapt_to_load else self.model_load, direction)
        xi_mf, xi_p = mixed_fractions_of_resistance(reference, constants, params)
        if self._shaper is None:
            points, last = self.reversals, self.direction
            temperature, fraction = self.previous_temperature, self.previous_fraction
            line = self.previous_line
        else:
            model = self._shaper.model
            points, last = model.reversals, model.direction
            temperature, fraction, line = model.temperature, model.xi_MF, None
        if not self._minor_loops:   # the search starts at the last T on the same branch
            near, line = (temperature, line) if direction == last else (None, None)
            sensed, line = temperature_with_tangent(xi_mf, xi_p, constants,
                                                    params.saturation_margin, near, line)
            return sensed, points, xi_mf, line
        if direction != last and temperature is not None:
            points = list(points)
            push_reversal(points, temperature, fraction, params.memory_depth)
        return invert_on_stack(xi_mf, xi_p, constants, direction, points,
                               params.saturation_margin) + (None,)

    def _shaped_demand(self, reference, load, direction):
        """(way [+1/-1], SensedTemperature): where the shaped compensator's model wire moves
        and the inverse it aims at (:mod:`.shaping`); no state change.

        Minor-loop: the way that brings the model's xi_MF towards R_ref's (heating lowers it;
        equal keeps the model's direction), and where that branch's inverse lies behind the
        model (a flat branch of its memory), the major branch's. Major: d_ref.
        """
        model = self._shaper.model
        if not self._minor_loops:
            return direction, self._invert(reference, load, direction)[0]
        params = self.params
        used = load if self.adapt_to_load else self.model_load
        target = mixed_fractions_of_resistance(reference, self._branches.get(used, HEATING),
                                               params)[0]
        way = (HEATING if target < model.xi_MF else
               COOLING if target > model.xi_MF else model.direction)
        sensed = self._invert(reference, load, way)[0]
        if not self._shaper.ahead(sensed.temperature, way):
            constants = self._branches.get(used, way)
            xi_mf, xi_p = mixed_fractions_of_resistance(reference, constants, params)
            major = temperature_of_fractions(xi_mf, xi_p, constants, params.saturation_margin)
            if self._shaper.ahead(major.temperature, way):
                sensed = major
        return way, sensed

    def _direction_for(self, reference):
        previous = self.previous_reference
        if previous is None or reference == previous:
            return self.direction
        return HEATING if reference < previous else COOLING

    def _no_reference_yet(self, reference):
        """True for R_ref <= 0 [ohm] before the first R_ref > 0 (see the module docstring)."""
        try:
            return self.previous_reference is None and reference <= 0.0
        except TypeError:  # not a number: the checks name it
            return False

    def _unconnected(self):
        """The outputs of a sample without a reference: P_ff = 0 W, T_ref = T_room, saturated."""
        return _new_tuple(FeedforwardOutputs, (0.0, self.params.T_room, True))

    def initial_outputs(self, reference, load):
        """Outputs before the first step (filter in steady state); the state is unchanged.

        ``reference`` R_ref [ohm], ``load`` [kg]; R_ref <= 0 gives the unconnected outputs.
        """
        if self.filter.previous_input is not None:
            raise RuntimeError("initial_outputs is only defined before the first step")
        if self._no_reference_yet(reference):
            require_nonnegative("load", load)
            return self._unconnected()
        reference = require_positive("R_ref", reference)
        load = require_nonnegative("load", load)
        direction = self._direction_for(reference)
        sensed = (self._invert(reference, load, direction)[0] if self._shaper is None
                  else self._shaped_demand(reference, load, direction)[1])
        temperature, saturated = self._demand(sensed)
        if self._shaper is not None:   # the model has not moved: its temperature, held
            power, resting = self._shaper.resting()
            return FeedforwardOutputs(power, resting, saturated or temperature != resting)
        return FeedforwardOutputs(self._power(temperature), temperature, saturated)

    def step(self, reference, load, step_size):
        """Compensate one sample: R_ref [ohm] and load [kg] at t_k, step h [s] -> outputs.

        Invalid inputs raise ``ValueError`` before any state changes. R_ref <= 0 before the
        first R_ref > 0 gives the unconnected outputs and one warning (module docstring).
        """
        if self.previous_reference is None and self._no_reference_yet(reference):
            fast_nonnegative("load", load)
            fast_positive("step_size", step_size)
            self.warning = None if self._unconnected_warned else (
                f"R_ref = {reference!r} ohm before any reference (an unconnected input): "
                f"P_ff = 0 W, T_ref = T_room, saturated; the compensator starts at the first "
                f"R_ref > 0")
            self._unconnected_warned = True
            return self._unconnected()
        reference = fast_positive("R_ref", reference)
        load = fast_nonnegative("load", load)
        step_size = fast_positive("step_size", step_size)
        sample = reference        # R_ref,k; the compensator works on the aim (anticipation)
        if self._anticipation is not None:
            reference = self._anticipation.aim(sample, step_size)
        direction = self._direction_for(reference)
        if self._shaper is None:
            sensed, points, fraction, line = self._invert(reference, load, direction)
        else:
            way, sensed = self._shaped_demand(reference, load, direction)
        warning = (validity_warning(self.params, -math.inf, -math.inf, load, self._load_before)
                   if load > self.params.load_max else None)
        temperature, saturated = self._demand(sensed)
        bounded = temperature != sensed.temperature
        if bounded and not self._bounded_before:
            bound = (f"T_ref = {sensed.temperature:.6g} degC demanded above validity.T_max = "
                     f"{self.params.T_max:g} degC (R_ref = {reference:.6g} ohm, load = {load:.6g} "
                     f"kg): bounded to T_max, saturated")
            warning = bound if warning is None else f"{warning}; {bound}"
        outside = None
        if self._data_unwarned:
            t_low, t_high, load_low, load_high = self._data_box
            if not (t_low <= temperature <= t_high and load_low <= load <= load_high):
                outside = data_range_warning(self.params, temperature, load, "T_ref")
        if outside is not None:
            warning = outside if warning is None else f"{warning}; {outside}"
        if self._shaper is None:
            output = self.filter.step(self._power(temperature), step_size)
            self.reversals = points
            self.previous_temperature = sensed.temperature
            self.previous_fraction = fraction
            self.previous_line = line
        else:
            output, temperature, moved = self._shaper.step(
                temperature, way, load if self.adapt_to_load else self.model_load, step_size)
            saturated = saturated or moved
        if self._anticipation is not None:
            self._anticipation.step(sample, step_size)
        self.direction = direction
        self.previous_reference = reference
        self.warning, self._load_before, self._bounded_before = warning, load, bounded
        if outside is not None:
            self._data_unwarned = False
        return _new_tuple(FeedforwardOutputs, (output, temperature, saturated))

    def _demand(self, sensed):
        """(T_ref [degC], saturated): the sensed temperature, bounded to validity.T_max
        (module docstring)."""
        if sensed.temperature > self.params.T_max:
            return self.params.T_max, True
        return sensed.temperature, sensed.saturated

    def _power(self, temperature):
        """v = (T_ref - T_room)/K_th [W]: the steady-state power of ``temperature`` [degC]."""
        return (temperature - self.params.T_room) / self.params.K_th

    def state(self):
        """JSON-ready hidden state (direction, last reference, reversal stack, the two-stage
        search's tangent at the last T_ref, filter; shaped, also the model wire's state as
        ``model``)."""
        line = self.previous_line
        state = {"format": STATE_FORMAT,
                 "direction": self.direction, "previous_reference": self.previous_reference,
                 "reversals": [list(point) for point in self.reversals],
                 "previous_temperature": self.previous_temperature,
                 "previous_fraction": self.previous_fraction,
                 "previous_exponent": None if line is None else line[0],
                 "previous_slope": None if line is None else line[1],
                 "filter": self.filter.state()}
        if self._shaper is not None:
            state["model"] = self._shaper.state()
        if self._anticipation is not None:
            state["anticipation"] = self._anticipation.state()
        return state

    def restore(self, state):
        """Restore a state saved by :meth:`state`.

        Every entry is checked first (direction +1/-1; R_ref > 0; T_ref above absolute
        zero; xi_MF in [0, 1]; the tangent's Lambda finite, its slope > 0 K; the stack; the
        filter's memory; shaped, the model wire's state as a plant's): a malformed state, or
        one of an earlier build, raises ``ValueError`` naming the entry and changes nothing.
        """
        check_format(state, STATE_FORMAT, "compensator state")
        shaped = self._shaper is not None
        anticipating = self._anticipation is not None
        read_entries(state, _STATE_ENTRIES + (("model",) if shaped else ())
                     + (("anticipation",) if anticipating else ()), what="compensator state")
        direction = read_direction(state)
        reference = read_optional_number(state, "previous_reference", 5e-324, unit="ohm")
        temperature = read_temperature(state, "previous_temperature", optional=True)
        fraction = read_optional_number(state, "previous_fraction", 0.0, 1.0)
        require_pair("previous_temperature", temperature, "previous_fraction", fraction)
        exponent = read_optional_number(state, "previous_exponent")
        slope = read_optional_number(state, "previous_slope", 5e-324, unit="K")
        require_pair("previous_exponent", exponent, "previous_slope", slope)
        points = read_points(state["reversals"], self.params.memory_depth, "reversals")
        if shaped:   # checked on a new model wire, taken only when everything else is good
            model = ReachableShaping(self.params, self._minor_loops, self.power_cap,
                                     self.model_load)
            try:
                model.restore(state["model"])
            except ValueError as error:
                raise StateError(f"state entry model: {error}") from None
        if anticipating:
            anticipation = TurnAnticipation(self._anticipation.lead)
            try:
                read_entries(state["anticipation"], ("earlier", "previous", "held"),
                             what="anticipation state")
                anticipation.restore(state["anticipation"], lambda table, key:
                                     read_optional_number(table, key, 5e-324, unit="ohm"))
            except ValueError as error:
                raise StateError(f"state entry anticipation: {error}") from None
        self.filter.restore(state["filter"])          # checks, then changes: the last check
        if shaped:
            self._shaper = model
        if anticipating:
            self._anticipation = anticipation
        self.direction, self.previous_reference = direction, reference
        self.previous_temperature, self.previous_fraction = temperature, fraction
        self.previous_line = None if slope is None else (exponent, slope)
        self.reversals = points
