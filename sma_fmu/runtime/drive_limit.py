"""A wire driver's current and voltage limit, and the linear (unswitched) driver it limits.

A bench driver feeds the wire from a supply of at most ``V_max_V`` [V] through a current
limit of ``I_max_A`` [A]. With the wire at resistance R, the power it can put in is

    P_cap(R) = min(I_max^2 R, V_max^2 / R)              [W]

(the current limit binds below R = V_max / I_max, the voltage limit above). A limit of 0
means none (its term is +inf). :meth:`DriveLimit.apply` gives the demand cut to P_cap(R);
a demand <= 0 W passes unchanged (the plant applies it as 0 W). R is the wire's resistance
at the start of the step (the plant's output R_k), held over the step as the power is.

:class:`LinearDriver` is the driver of ``[drive] kind = "power"`` with a limit: the demand
itself, cut to P_cap(R). The PWM driver (:mod:`.pwm`) takes the same limit on its on-power.
Both are IEEE products and quotients in a fixed order ((I^2) R, (V^2) / R), so C and numpy
give the same bits.
"""
import math

from .checks import fast_finite, fast_positive, require_nonnegative
from .state_entries import read_entries, read_number

__all__ = ["DriveLimit", "LinearDriver"]


class DriveLimit:
    """The current limit ``I_max_A`` [A] and voltage limit ``V_max_V`` [V] of a driver (0: none)."""

    def __init__(self, I_max_A=0.0, V_max_V=0.0):
        self.I_max = require_nonnegative("I_max_A", I_max_A)
        self.V_max = require_nonnegative("V_max_V", V_max_V)
        self.current_squared = self.I_max * self.I_max if self.I_max else math.inf   # [A^2]
        self.voltage_squared = self.V_max * self.V_max if self.V_max else math.inf   # [V^2]
        self.limited = bool(self.I_max or self.V_max)

    def cap(self, resistance):
        """P_cap [W] = min(I_max^2 R, V_max^2 / R) at ``resistance`` R [ohm] (> 0; unchecked)."""
        by_current = self.current_squared * resistance
        by_voltage = self.voltage_squared / resistance
        return by_current if by_current <= by_voltage else by_voltage

    def apply(self, power, resistance):
        """``power`` [W] cut to :meth:`cap` at ``resistance`` [ohm] (unchecked: the hot path)."""
        cap = self.cap(resistance)
        return power if power <= cap else cap


class LinearDriver:
    """The demanded power itself, within a :class:`DriveLimit` (``[drive] kind = "power"``)."""

    def __init__(self, limit):
        self.limit = limit
        self.power = 0.0        # the power of the last step [W]

    def step(self, demand_W, time_s, step_size, resistance):
        """P_in [W] over [time_s, time_s + step_size) for ``demand_W`` [W] held, at the wire's
        ``resistance`` [ohm]. Non-finite demand or time, a step <= 0 or (with a limit) an R
        that is not finite and > 0 raise ``ValueError``."""
        demand_W = fast_finite("P_demand", demand_W)
        fast_finite("time", time_s)
        fast_positive("step_size", step_size)
        if self.limit.limited:
            demand_W = self.limit.apply(demand_W, fast_positive("R", resistance))
        self.power = demand_W
        return demand_W

    def state(self):
        """JSON-ready state: the last step's power [W]."""
        return {"power": self.power}

    def restore(self, state):
        """Restore a state saved by :meth:`state` (``ValueError`` naming a bad entry; no change)."""
        read_entries(state, ("power",), what="driver state")
        self.power = read_number(state, "power", unit="W")
