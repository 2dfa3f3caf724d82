"""PI feedback with a power clamp at 0 W and conditional integration (spec section 10).

    e = R - R_ref (positive error -> more heat)
    u_raw = u_ff + Kp e_k + Ki I_k,   u = max(0, u_raw)
    I_(k+1) = I_k + h e_k, except while clamped (u_raw < 0) with e_k <= 0, where I stays.

The integrator is forward Euler: python-control's sample_system(Kp + Ki/s, h, 'zoh').
The library loop calls :meth:`PIController.step` with e_k; the SmaPiController FMU calls
:meth:`PIController.sample`, which checks its inputs first, and shows :meth:`PIController.output`
before its first step.
"""
from .checks import fast_finite, fast_positive, require_finite, require_nonnegative
from .state_entries import read_entries, read_number

__all__ = ["PIController"]


class PIController:
    """Discrete PI with anti-windup; gains Kp [W/ohm], Ki [W/(ohm.s)]."""

    warning = None  # a PI has no validity range: no step ever warns (the plant's has one)

    def __init__(self, Kp, Ki):
        self.Kp = require_nonnegative("Kp", Kp)
        self.Ki = require_nonnegative("Ki", Ki)
        self.integral = 0.0   # I_k [ohm.s]

    def _unclamped(self, error, feedforward):
        """(u_raw = u_ff + Kp e + Ki I, feedback part Kp e + Ki I) [W] with the present integral."""
        feedback = self.Kp * error + self.Ki * self.integral
        return feedforward + feedback, feedback

    def output(self, error, feedforward):
        """(power u_k [W], feedback part Kp e + Ki I [W]) with the present integral; no change.

        ``error`` e_k [ohm], ``feedforward`` u_ff,k [W].
        """
        raw, feedback = self._unclamped(error, feedforward)
        return (0.0 if raw < 0.0 else raw), feedback

    def step(self, error, feedforward, step_size):
        """Return (power u_k [W], feedback part Kp e + Ki I [W]) and advance the integrator.

        ``error`` e_k [ohm], ``feedforward`` u_ff,k [W], ``step_size`` h [s].
        """
        raw, feedback = self._unclamped(error, feedforward)
        clamped = raw < 0.0
        if not clamped or error > 0.0:
            self.integral += step_size * error
        return (0.0 if clamped else raw), feedback

    def sample(self, resistance, reference, feedforward, step_size):
        """:meth:`step` for R [ohm], R_ref [ohm], u_ff [W] and h [s], each checked first.

        Non-finite inputs or a step <= 0 raise ``ValueError`` naming the input; the state
        is then unchanged.
        """
        resistance = fast_finite("R", resistance)
        reference = fast_finite("R_ref", reference)
        feedforward = fast_finite("P_ff", feedforward)
        step_size = fast_positive("step_size", step_size)
        return self.step(resistance - reference, feedforward, step_size)

    def preview(self, resistance, reference, feedforward):
        """:meth:`output` for R [ohm], R_ref [ohm] and u_ff [W], each checked first."""
        error = require_finite("R", resistance) - require_finite("R_ref", reference)
        return self.output(error, require_finite("P_ff", feedforward))

    def state(self):
        """JSON-ready hidden state (the integral I_k [ohm.s])."""
        return {"integral": self.integral}

    def restore(self, state):
        """Restore a state saved by :meth:`state` (``ValueError`` naming a bad entry; no change)."""
        read_entries(state, ("integral",), what="PI state")
        self.integral = read_number(state, "integral", unit="ohm.s")
