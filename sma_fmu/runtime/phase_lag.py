"""Phase-lag compensator Cpl(s) = (alpha s + 1)/(beta s + 1), Tustin at step h (spec section 10).

    c = 2/h,  y_k = b0 v_k + b1 v_(k-1) - a1 y_(k-1)
    b0 = (alpha c + 1)/(beta c + 1),  b1 = (1 - alpha c)/(beta c + 1),  a1 = (1 - beta c)/(beta c + 1)

The filter starts in steady state at its first input: v_(-1) = y_(-1) = v_0.
"""
from .checks import require_nonnegative, require_positive
from .state_entries import read_entries, read_optional_number, require_pair

__all__ = ["tustin_coefficients", "PhaseLagFilter"]

_INF = float("inf")


def tustin_coefficients(alpha, beta, step_size):
    """(b0, b1, a1) of Cpl(s) for lead time ``alpha`` [s], lag time ``beta`` [s], step [s]."""
    # the formulas above multiplied through by h/2: finite for every step, however small
    half = 0.5 * step_size
    denominator = beta + half
    return (alpha + half) / denominator, (half - alpha) / denominator, (half - beta) / denominator


class PhaseLagFilter:
    """Stateful Tustin realisation of Cpl(s); input and output in the same unit (here W)."""

    def __init__(self, alpha, beta):
        self.alpha = require_nonnegative("alpha", alpha)
        self.beta = require_positive("beta", beta)
        self.previous_input = None    # v_(k-1); None before the first sample
        self.previous_output = None   # y_(k-1)
        self._step_size = None
        self._coefficients = None

    def step(self, value, step_size):
        """Filter one sample ``value`` taken at the start of a step of ``step_size`` [s]."""
        if step_size != self._step_size:
            self._coefficients = tustin_coefficients(self.alpha, self.beta, step_size)
            self._step_size = step_size
        b0, b1, a1 = self._coefficients
        first = self.previous_input is None  # steady state at the first input
        output = (b0 * value + b1 * (value if first else self.previous_input)
                  - a1 * (value if first else self.previous_output))
        if not -_INF < output < _INF:
            raise ValueError(f"phase-lag filter output {output!r} W is not finite (alpha = "
                             f"{self.alpha!r} s, beta = {self.beta!r} s, step {step_size!r} s)")
        self.previous_input = value
        self.previous_output = output
        return output

    def state(self):
        """JSON-ready filter memory."""
        return {"previous_input": self.previous_input, "previous_output": self.previous_output}

    def restore(self, state):
        """Restore memory saved by :meth:`state`: both entries null (before the first
        sample) or both finite numbers [W]; else ``ValueError`` naming the entry, no change."""
        read_entries(state, ("previous_input", "previous_output"), what="filter state")
        previous_input = read_optional_number(state, "previous_input", unit="W")
        previous_output = read_optional_number(state, "previous_output", unit="W")
        require_pair("previous_input", previous_input, "previous_output", previous_output,
                     what="filter state")
        self.previous_input, self.previous_output = previous_input, previous_output
