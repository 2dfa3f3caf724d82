"""Anticipating the reference's lower turn, for the shaped compensator (``anticipation`` > 0).

The wire cools only by convection, so after R_ref turns at its low end (the wire must cool
for R to rise) a compensator that starts cooling at the turn lags by the time passive
cooling needs to cross the hysteresis (0.4-0.5 s on the paper's reference). The best
trajectory (the tracking bound's) starts cooling before the turn. This block does that from
the reference's own past samples, with no preview of the future: from the last three samples
(h apart)

    R' = (R_k - R_k-2) / (2 h),    R'' = (R_k - 2 R_k-1 + R_k-2) / h^2

where the reference falls towards a minimum (R' < 0 < R'') that, at this curvature, it
reaches within the anticipation time L but not within one sample (h <= -R'/R'' < L), the
compensator aims at the parabola's value L ahead, R_k + R' L + R'' L^2 / 2, instead of R_k.
The one-sample floor tells a turn from a jump: after a step, a kink or a jump (a stroke
reference mapped onto the other branch jumps where it turns) the three samples give
-R'/R'' = h/2, and a parabola through them would aim thousands of ohms away
(R_k - (L^2/(2 h^2) - L/(2 h)) dR for a step dR: 11,000 ohm per ohm at L = 0.15 s, h = 1 ms). Once the reference has turned, the
aim stays at the last anticipated value until R_ref catches up with it (no step back, which
would read as heating). **choice**: the lower turn only: at the upper turn the wire heats,
as fast as the driver allows, and anticipating it made tracking worse on the paper's
reference. A reference without curvature (steps, ramps, set-points) is never anticipated.
"""
from .checks import require_nonnegative

__all__ = ["TurnAnticipation"]


class TurnAnticipation:
    """The aim R_aim [ohm] for each R_ref sample, ``lead`` L [s] ahead near a lower turn."""

    def __init__(self, lead):
        self.lead = require_nonnegative("anticipation", lead)
        self.earlier = None     # R_ref,k-2 [ohm]
        self.previous = None    # R_ref,k-1 [ohm]
        self.held = None        # the last anticipated aim [ohm], held after the turn

    def _ahead(self, reference, step_size):
        """R_k + R' L + R'' L^2 / 2 [ohm] near a lower turn between h and L ahead, else R_k."""
        earlier, previous, lead = self.earlier, self.previous, self.lead
        if earlier is None:
            return reference
        slope = (reference - earlier) / (2.0 * step_size)
        curvature = (reference - 2.0 * previous + earlier) / (step_size * step_size)
        if slope < 0.0 < curvature and step_size * curvature <= -slope < curvature * lead:
            return reference + slope * lead + 0.5 * curvature * lead * lead
        return reference

    def aim(self, reference, step_size):
        """Preview of :meth:`step`: the aim [ohm] for ``reference`` [ohm]; no state change."""
        return self._next(reference, step_size)[0]

    def _next(self, reference, step_size):
        aim = self._ahead(reference, step_size)
        if aim == reference and self.held is not None and reference < self.held:
            return self.held, self.held
        return aim, (None if aim == reference else aim)

    def step(self, reference, step_size):
        """The aim [ohm] for the sample ``reference`` [ohm], samples ``step_size`` [s] apart."""
        aim, self.held = self._next(reference, step_size)
        self.earlier, self.previous = self.previous, reference
        return aim

    def state(self):
        """JSON-ready state: the last two samples and the held aim [ohm] (null: none)."""
        return {"earlier": self.earlier, "previous": self.previous, "held": self.held}

    def restore(self, state, read_number):
        """Restore :meth:`state`'s entries, each read by ``read_number(state, key)``."""
        values = {key: read_number(state, key) for key in ("earlier", "previous", "held")}
        self.earlier, self.previous, self.held = (values["earlier"], values["previous"],
                                                  values["held"])
