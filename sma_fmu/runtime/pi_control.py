"""PI feedback with a power clamp at 0 W and conditional integration (spec section 10).

    e = R - R_ref (positive error -> more heat)
    u_raw = u_ff + Kp e_k + Ki I_k,   u = max(0, u_raw)
    I_(k+1) = I_k + h e_k, except while clamped (u_raw < 0) with e_k <= 0, where I stays.

The integrator is forward Euler: python-control's sample_system(Kp + Ki/s, h, 'zoh').
"""
from .checks import require_nonnegative

__all__ = ["PIController"]


class PIController:
    """Discrete PI with anti-windup; gains Kp [W/ohm], Ki [W/(ohm.s)]."""

    def __init__(self, Kp, Ki):
        self.Kp = require_nonnegative("Kp", Kp)
        self.Ki = require_nonnegative("Ki", Ki)
        self.integral = 0.0   # I_k [ohm.s]

    def step(self, error, feedforward, step_size):
        """Return (power u_k [W], feedback part Kp e + Ki I [W]) and advance the integrator.

        ``error`` e_k [ohm], ``feedforward`` u_ff,k [W], ``step_size`` h [s].
        """
        feedback = self.Kp * error + self.Ki * self.integral
        raw = feedforward + feedback
        if raw < 0.0:
            if error > 0.0:
                self.integral += step_size * error
            return 0.0, feedback
        self.integral += step_size * error
        return raw, feedback
