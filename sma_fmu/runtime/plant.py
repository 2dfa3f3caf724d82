"""Stateful plant: thermal model + resistance hysteresis of one wire (spec sections 4, 6, 9, 11).

One :meth:`PlantStepper.step` advances from t_k to t_k + h with the input power and the
load held, and evaluates the outputs at the end of the step with the held load.
The direction is sgn(T+ - T) (unchanged when T+ = T). In mode "continuous" (the
default) a reversal found in a step pushes (T_k, xi_MF_k) onto the stack of reversal
points, closed loops are wiped out, and the branch of the top point follows (section 6,
:mod:`.minor_loops`: return-point memory); in mode "switch" (the paper's) the fractions
follow the major branch of that direction. A power of 0 W or less is applied as 0 W (the
paper's rule), so a compensator output wired straight to the plant is valid; non-finite
power is rejected, and so is a finite power so large that the temperature would leave the
floating-point range. Leaving the validity range (T above ``validity.T_max``, or a load above the one
``validity.stress_max`` gives) sets :attr:`PlantStepper.warning` for that one step, so the
FMU can warn once per excursion. A wire that gives the range its data covered
(``validity.T_data_min`` ...) sets it once more, the first time (the start included) T or the
load lies outside that range, and never again in that stepper's life (a restored state
does not re-arm it).
"""
import math
from collections import namedtuple

from .checks import fast_finite, fast_nonnegative, fast_positive, require_mode, require_nonnegative
from .constant_load import BranchCache, branch_fractions, require_temperature, two_stage_fractions
from .constants import COOLING, HEATING, KELVIN_OFFSET
from .model_terms import length_of
from .minor_loops import (branch_of, fractions_on_branch, push_reversal, read_points,
                          wipe_out)
from .state_entries import (StateError, check_format, read_direction, read_entries, read_number,
                            read_temperature)
from .thermal import step_decay, thermal_step
from .validity import data_box, data_range_warning, validity_warning

__all__ = ["PlantOutputs", "PlantStepper", "STATE_FORMAT", "branch_length"]

STATE_FORMAT = "sma-fmu plant state 2: reversal stack"   # what state() writes, restore() reads
_STATE_ENTRIES = ("format", "temperature", "direction", "reversals", "load", "xi_MF", "xi_P",
                  "power")

PlantOutputs = namedtuple("PlantOutputs", ["R", "T", "x", "xi_P", "xi_M", "xi_F", "P", "heating"])
_new_tuple = tuple.__new__
PlantOutputs.__doc__ = """Plant outputs at a communication point.

R : resistance [ohm]; T : temperature [degC]; x : wire length [m];
xi_P, xi_M, xi_F : phase fractions [1]; P : power applied over the last step, max(0, P_in) [W]
(0 before the first step); heating : True while dT/dt > 0 (last sign kept).
"""


def branch_length(temperature, xi_p, xi_m, xi_f, constants, params):
    """Wire length x [m] of the fractions [1] at ``temperature`` [degC] on a branch with
    :class:`~.constant_load.BranchConstants` (the strain terms' stressed lengths and thermal
    expansion where the wire has them)."""
    if constants.strain is None:
        return params.l_P * xi_p + params.l_M * xi_m + params.l_F * xi_f
    return length_of(temperature, xi_p, xi_m, xi_f, constants.strain)


class PlantStepper:
    """The SMA wire actuator: electric power and load in, resistance and state out.

    Parameters
    ----------
    params : WireParameters
    T_start : float, optional
        Initial temperature [degC]; default the room temperature T_room.
    mode : "continuous" | "switch"
        Hysteresis mode: continuous minor loops (default: it holds a constant set-point)
        or the paper's branch switch (which limit-cycles at a constant set-point).
    load : float
        Load during initialization [kg]; the initial outputs reflect it.

    The wire starts heating, on the major branch, with an empty reversal memory
    (:attr:`reversals`, at most ``params.memory_depth`` points). ``warning`` is a message for
    the one step (or the start) in which the temperature rises above ``params.T_max`` or the
    load above ``params.load_max``, or the first one outside the data range, else None.
    """

    def __init__(self, params, T_start=None, mode="continuous", load=0.0):
        self.params = params
        self.mode = require_mode(mode, "hysteresis mode")
        self._continuous = self.mode == "continuous"
        self._branches = BranchCache(params)
        self._decay = (None, None)
        self.temperature = (params.T_room if T_start is None
                            else require_temperature("T_start", T_start))
        self.direction = HEATING
        self.reversals = []          # the stack of ReversalPoint (T [degC], xi_MF [1])
        self._branch = None          # the Branch of the top point (None: the major branch)
        self._branch_key = None      # the BranchConstants it was made for
        self.load = require_nonnegative("load", load)
        self.power = 0.0
        constants = self._branches.get(self.load, HEATING)
        self.xi_MF, self.xi_P = branch_fractions(self.temperature, constants)
        self.outputs = self._evaluate(constants)
        self.warning = None
        self._data_unwarned = params.data_range   # the data-range warning is still to come
        self._data_box = data_box(params)    # its bounds, missing ones infinite
        self._check_validity(-math.inf, -math.inf)
        if self._data_unwarned:
            self._check_data_range()

    def _check_validity(self, before, load_before):
        """Set :attr:`warning` when the temperature crosses ``T_max`` or the load crosses
        ``load_max`` upwards (once per excursion)."""
        self.warning = validity_warning(self.params, self.temperature, before, self.load,
                                        load_before)

    def _check_data_range(self):
        """Add the data-range warning to :attr:`warning` the first time T or the load is
        outside the range the wire's data covered (once per stepper)."""
        warning = data_range_warning(self.params, self.temperature, self.load)
        if warning is not None:
            self._data_unwarned = False
            self.warning = warning if self.warning is None else f"{self.warning}; {warning}"

    def step(self, power, load, step_size):
        """Advance one step of ``step_size`` [s] with ``power`` [W] and ``load`` [kg] held.

        A power <= 0 W is applied as 0 W. Invalid inputs (non-finite power, negative or
        non-finite load, step <= 0) raise ``ValueError`` before any state changes.
        """
        power = fast_finite("P_in", power)
        if not power > 0.0:
            power = 0.0
        load = fast_nonnegative("load", load)
        step_size = fast_positive("step_size", step_size)
        params = self.params
        if step_size != self._decay[0]:
            self._decay = (step_size, step_decay(step_size, params.tau_th))
        before = self.temperature
        after = thermal_step(before, power, params.T_room, params.K_th, self._decay[1])
        if not -math.inf < after < math.inf:
            raise ValueError(f"P_in = {power!r} W over {step_size!r} s would take the wire "
                             "temperature out of the floating-point range")
        direction = HEATING if after > before else (COOLING if after < before else self.direction)
        constants = self._branches.get(load, direction)
        if self._continuous:
            points = self.reversals
            changed = direction != self.direction
            if changed:
                push_reversal(points, before, self.xi_MF, params.memory_depth)
            if len(points) >= 2 and wipe_out(points, after, direction):
                changed = True
            if not points:   # two stages: branch_fractions' own call, without the layer
                xi_mf, xi_p = (branch_fractions(after, constants) if constants.stages is None
                               else two_stage_fractions(1.0 / (after + KELVIN_OFFSET), constants))
            else:
                if changed or constants is not self._branch_key:
                    self._branch = branch_of(points, len(points), constants, direction)
                    self._branch_key = constants
                xi_mf, xi_p = fractions_on_branch(after, constants, direction, self._branch)
        else:
            xi_mf, xi_p = (branch_fractions(after, constants) if constants.stages is None
                           else two_stage_fractions(1.0 / (after + KELVIN_OFFSET), constants))
        load_before = self.load
        self.temperature, self.direction, self.load, self.power = (
            after, direction, load, power)
        self.xi_MF, self.xi_P = xi_mf, xi_p
        self.outputs = self._evaluate(constants)
        self.warning = None
        if after > params.T_max or load > params.load_max:
            self._check_validity(before, load_before)
        if self._data_unwarned:
            t_low, t_high, load_low, load_high = self._data_box
            if not (t_low <= after <= t_high and load_low <= load <= load_high):
                self._check_data_range()
        return self.outputs

    def _evaluate(self, constants):
        params = self.params
        xi_p = self.xi_P
        xi_m = 0.5 * self.xi_MF
        xi_f = constants.xi_F_min + xi_m
        strain = constants.strain   # branch_length, written out: it runs at every step
        length = (params.l_P * xi_p + params.l_M * xi_m + params.l_F * xi_f if strain is None
                  else length_of(self.temperature, xi_p, xi_m, xi_f, strain))
        # tuple.__new__ builds the namedtuple in C: a third of the cost of PlantOutputs(...)
        return _new_tuple(PlantOutputs, (
            params.R_P * xi_p + params.R_M * xi_m + params.R_F * xi_f,
            self.temperature,
            length,
            xi_p, xi_m, xi_f,
            self.power,
            self.direction == HEATING,
        ))

    def state(self):
        """JSON-ready hidden state (temperature, direction, reversal stack, fractions, load)."""
        return {
            "format": STATE_FORMAT,
            "temperature": self.temperature,
            "direction": self.direction,
            "reversals": [list(point) for point in self.reversals],
            "load": self.load,
            "xi_MF": self.xi_MF,
            "xi_P": self.xi_P,
            "power": self.power,
        }

    def restore(self, state):
        """Restore a state saved by :meth:`state` and re-evaluate the outputs.

        Every entry is checked first (kinds; T above absolute zero and at most
        ``validity.T_max``, where the model is valid; a load the model covers; fractions in
        [0, M] with xi_MF + xi_P = M; a well-formed stack of at most ``memory_depth``
        points): a malformed state raises ``ValueError`` naming the entry and changes nothing. So does a state of an earlier build (one reversal, no stack),
        which is never misread.
        """
        check_format(state, STATE_FORMAT, "plant state")
        read_entries(state, _STATE_ENTRIES, what="plant state")
        temperature = read_temperature(state, "temperature", high=self.params.T_max)
        direction = read_direction(state)
        load = read_number(state, "load", 0.0, unit="kg")
        try:
            constants = self._branches.get(load, direction)
        except ValueError as error:
            raise StateError(f"state entry load: {error}") from None
        total = constants.M
        xi_mf = read_number(state, "xi_MF", 0.0, total)
        xi_p = read_number(state, "xi_P", 0.0, total)
        if abs(xi_mf + xi_p - total) > 1e-9:
            raise StateError(f"state entries xi_MF = {xi_mf!r} and xi_P = {xi_p!r} must add up to "
                             f"M = 1 - xi_Fmin(load) = {total!r}")
        power = read_number(state, "power", 0.0, unit="W")
        points = read_points(state["reversals"], self.params.memory_depth, "reversals")
        self.temperature, self.direction, self.load = temperature, direction, load
        self.xi_MF, self.xi_P, self.power = xi_mf, xi_p, power
        self.reversals = points
        self._branch_key = None
        self.outputs = self._evaluate(constants)
