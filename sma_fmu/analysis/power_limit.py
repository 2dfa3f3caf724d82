"""The most power a driver can give the wire, for the tracking bound: a cap, a current limit,
a voltage limit.

    P_max(R) = min(P_cap, I_max^2 R, V_max^2 / R)        [W]   (a limit not set: +inf)

R is the wire's resistance at the start of the step (the plant's R_k), as the runtime's
:class:`~sma_fmu.runtime.drive_limit.DriveLimit` takes it. Over an interval of resistances
[a, b] the most power is at most min(P_cap, I_max^2 b, V_max^2 / a) (:meth:`PowerLimit.most`)
and at least min(P_cap, I_max^2 a, V_max^2 / b) (:meth:`PowerLimit.least`): the dynamic
programs use the first for a lower bound (a relaxation: every true move stays possible) and
the second for a path the plant can follow.
"""
import math
from dataclasses import dataclass

import numpy as np

__all__ = ["PowerLimit"]


def _squared(limit):
    return math.inf if limit is None or limit == 0.0 else limit * limit


@dataclass(frozen=True)
class PowerLimit:
    """``power_W`` P_cap [W], ``current_A`` I_max [A], ``voltage_V`` V_max [V]; None: not set."""

    power_W: float = None
    current_A: float = None
    voltage_V: float = None

    @classmethod
    def of(cls, power_cap=None, scenario=None, current_A=None, voltage_V=None):
        """``power_cap`` (a float, None or a :class:`PowerLimit`), with the current and
        voltage limits given here, else those of ``scenario``'s ``[drive]``."""
        if isinstance(power_cap, PowerLimit):
            return power_cap
        drive = None if scenario is None else scenario.drive
        if current_A is None and drive is not None and drive.I_max_A:
            current_A = drive.I_max_A
        if voltage_V is None and drive is not None and drive.V_max_V:
            voltage_V = drive.V_max_V
        return cls(power_cap, current_A or None, voltage_V or None)

    @property
    def by_resistance(self):
        """True when the most power depends on R (a current or voltage limit)."""
        return self.current_A is not None or self.voltage_V is not None

    @property
    def cap(self):
        """P_cap [W] (+inf when not set)."""
        return math.inf if self.power_W is None else self.power_W

    def at(self, resistance):
        """P_max [W] at ``resistance`` [ohm] (a number or an array)."""
        return self.most(resistance, resistance)

    def most(self, low, high):
        """An upper bound [W] of P_max over R in [``low``, ``high``] [ohm] (arrays too)."""
        return np.minimum(self.cap, np.minimum(_squared(self.current_A) * np.asarray(high),
                                               _squared(self.voltage_V) / np.asarray(low)))

    def least(self, low, high):
        """A lower bound [W] of P_max over R in [``low``, ``high``] [ohm] (arrays too)."""
        return self.most(high, low)

    def describe(self):
        """The limit in words: "P <= 10 W, I <= 0.5 A, V <= 24 V", or "unlimited"."""
        parts = [f"{name} <= {value:g} {unit}" for name, value, unit in (
            ("P", self.power_W, "W"), ("I", self.current_A, "A"), ("V", self.voltage_V, "V"))
            if value is not None]
        return ", ".join(parts) if parts else "unlimited"
