"""The compensator's demand shaped into what the wire can reach (``shaping = "reachable"``).

The paper's compensator demands T_ref = inverse(R_ref) and turns it into power through the
phase-lag filter. Where T_ref falls faster than passive cooling allows, the wire cannot
follow, and the minor-loop inverse's memory (the reversals it assumes the wire made) drifts
away from the wire's. Shaped, the compensator keeps a model of the wire, the runtime's own
:class:`~.plant.PlantStepper` (mode "switch" for the major inverse, "continuous" for the
minor-loop one), and per sample, one model-predictive step (horizon one step):

1. T* is the inverse of R_ref on the branch the model wire follows in the reference's
   direction d_ref (the compensator's :meth:`~.feedforward.FeedforwardStepper._invert`
   with the model's memory: its stack, its present state pushed when d_ref reverses it);
2. the aim is T* when it lies on d_ref's side of the model's temperature T_m, else T_m
   (**choice**: the model moves only the way the reference does; against it, in mode
   "switch", it would jump to the other branch and chatter);
3. the power is the thermal model's exact one-step inverse towards the aim
   (:func:`~.thermal.power_to_reach`), clamped into [0, P_max]: the temperatures one step
   can reach, cooling no faster than convection (P = 0) and heating no faster than the
   driver (P_max; None: no limit);
4. the model steps with that power and the load, by the plant's rules (reversals, wiping
   out): its memory is the one the wire has when it gets that power.

P_ff is that power (no phase-lag filter: alpha and beta are not used) and T_ref the model's
temperature after the step. With no feedback and no model error the plant follows the
model bit for bit. The model starts at T_room, heating, on the major branch, as a plant
with the default start does.
"""
from .checks import require_positive
from .constants import HEATING
from .plant import PlantStepper
from .thermal import power_to_reach, step_decay

__all__ = ["SHAPINGS", "require_shaping", "require_power_cap", "ReachableShaping"]

SHAPINGS = ("none", "reachable")


def require_shaping(shaping):
    """Return ``shaping`` if it is one of :data:`SHAPINGS`, else raise ``ValueError``."""
    if isinstance(shaping, str) and shaping in SHAPINGS:
        return shaping
    raise ValueError(f"shaping must be one of {', '.join(SHAPINGS)}, got {shaping!r}")


def require_power_cap(power_cap, shaping):
    """P_max [W]: None (no limit) or a finite number > 0, and only with shaping "reachable"."""
    if power_cap is None:
        return None
    power_cap = require_positive("power_cap", power_cap)
    if shaping != "reachable":
        raise ValueError(f"power_cap = {power_cap!r} W needs shaping 'reachable', "
                         f"got {shaping!r}")
    return power_cap


class ReachableShaping:
    """The model wire of a shaped compensator and its one-step choice of power.

    ``params`` the compensator's WireParameters; ``minor_loops``: the model keeps minor
    loops (mode "continuous") or switches branch (mode "switch"); ``power_cap`` P_max [W]
    or None; ``load`` [kg] the model starts under.
    """

    def __init__(self, params, minor_loops, power_cap, load):
        self.params = params
        self.power_cap = power_cap
        self.model = PlantStepper(params, None, "continuous" if minor_loops else "switch", load)
        self._decay = (None, None)

    def step(self, demand, direction, load, step_size):
        """(P [W], T_ref [degC], moved) for the demand T* [degC] in ``direction`` (+1/-1).

        ``moved``: the aim was held (T* on the other side of the model) or the power clamped,
        so the model does not reach T*. The model steps with ``load`` [kg] over ``step_size`` [s].
        """
        params, model = self.params, self.model
        if step_size != self._decay[0]:
            self._decay = (step_size, step_decay(step_size, params.tau_th))
        now = model.temperature
        ahead = self.ahead(demand, direction)
        power = power_to_reach(now, demand if ahead else now, params.T_room, params.K_th,
                               self._decay[1])
        moved = not ahead and demand != now
        if not power > 0.0:
            power, moved = 0.0, moved or power < 0.0
        elif self.power_cap is not None and power > self.power_cap:
            power, moved = self.power_cap, True
        model.step(power, load, step_size)
        return power, model.temperature, moved

    def ahead(self, temperature, direction):
        """True when ``temperature`` [degC] lies beyond the model's in ``direction``."""
        now = self.model.temperature
        return temperature > now if direction == HEATING else temperature < now

    def resting(self):
        """(P [W], T_ref [degC]) before the first step: the power that holds the model's
        temperature, and that temperature."""
        temperature = self.model.temperature
        return (temperature - self.params.T_room) / self.params.K_th, temperature

    def state(self):
        """The model's state (:meth:`PlantStepper.state`)."""
        return self.model.state()

    def restore(self, state):
        """Restore the model (:meth:`PlantStepper.restore`: checks every entry first)."""
        self.model.restore(state)
