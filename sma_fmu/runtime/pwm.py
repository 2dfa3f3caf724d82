"""A PWM wire driver: the demanded power in, the mean power of the PWM wave over a step out.

Almost every SMA driver heats its wire by switching a fixed supply on and off. This driver
switches between ``peak_W`` and 0 W at ``frequency_Hz``; periods start at t = j / f
(j = 0, 1, ...). At the start of each period the demanded power [W] sets that period's duty

    d_j = clip(P_demand / peak_W, 0, 1),   the wave is on over [j/f, (j + d_j)/f)

and a period keeps its duty to its end, even when the demand changes inside it. Over a
co-simulation step [t, t + h) with the demand held, :meth:`PwmDriver.step` returns the exact
mean of the wave: a period much shorter than the step gives the demanded mean power (up to
the partial periods at the step's ends), a period longer than the step a square wave.
Times within :data:`PERIOD_TOLERANCE` periods of a period start count as that start, so
t = k h meets j / f although neither is exact in binary.

With a :class:`~.drive_limit.DriveLimit` (a current-limited supply), the wave's on-power is
``peak_W`` cut to the limit at the wire's resistance R at the step's start,
min(peak_W, I_max^2 R, V_max^2 / R): the duty still comes from ``peak_W`` (the controller
does not know its supply sags), the mean is that on-power times the on-fraction.
"""
import math

from .checks import fast_finite, fast_positive, require_positive
from .state_entries import read_entries

__all__ = ["PwmDriver", "PERIOD_TOLERANCE", "DRIVE_KINDS", "MIN_FREQUENCY_HZ", "MAX_FREQUENCY_HZ"]

PERIOD_TOLERANCE = 1e-9   # [periods]
# choice: from one period in ~11.6 days to 1 GHz, far beyond any wire driver either way; the
# period index t f stays an exact-enough float over the longest run (2e6 steps)
MIN_FREQUENCY_HZ = 1e-6
MAX_FREQUENCY_HZ = 1e9
DRIVE_KINDS = ("power", "pwm")


class PwmDriver:
    """PWM of the heating power at ``frequency_Hz`` [Hz] between 0 and ``peak_W`` [W]."""

    def __init__(self, frequency_Hz, peak_W, limit=None):
        self.frequency = require_positive("frequency_Hz", frequency_Hz)
        if not MIN_FREQUENCY_HZ <= self.frequency <= MAX_FREQUENCY_HZ:
            raise ValueError(f"frequency_Hz must be in [{MIN_FREQUENCY_HZ:g}, {MAX_FREQUENCY_HZ:g}] "
                             f"Hz, got {frequency_Hz!r}")
        self.peak = require_positive("peak_W", peak_W)
        self.period = 1.0 / self.frequency
        self.limit = limit if limit is not None and limit.limited else None   # DriveLimit
        self.held = None      # (index j, duty) of the period in progress at the last step's end
        self.power = 0.0      # mean power of the last step [W]

    def _index(self, time_s):
        """(j, starts): the period containing ``time_s`` [s] and whether it starts there."""
        position = time_s * self.frequency
        nearest = round(position)
        if abs(position - nearest) <= PERIOD_TOLERANCE * max(1.0, abs(position)):
            return int(nearest), True
        return int(math.floor(position)), False

    def duty_of(self, demand_W):
        """The duty [1] a period starting now takes from ``demand_W`` [W]: clip(P/peak, 0, 1)."""
        duty = demand_W / self.peak
        return 0.0 if not duty > 0.0 else (1.0 if duty > 1.0 else duty)

    def _on_time(self, index, duty, start, end):
        """On-time [s] of period ``index`` with ``duty`` inside [start, end)."""
        begin = index * self.period
        return max(0.0, min(begin + duty * self.period, end) - max(begin, start))

    def step(self, demand_W, time_s, step_size, resistance=None):
        """Mean power [W] over [time_s, time_s + step_size) with ``demand_W`` held.

        The period in progress at ``time_s`` keeps the duty it was given at its start (a
        first step, or a time that does not follow the last step, gives it the present
        demand's). ``resistance`` R [ohm] of the wire sets the on-power under a limit (else
        unused). Non-finite demand or time, a step <= 0, or (with a limit) an R that is not
        finite and > 0, raise ``ValueError``.
        """
        demand_W = fast_finite("P_demand", demand_W)
        time_s = fast_finite("time", time_s)
        step_size = fast_positive("step_size", step_size)
        on_power = self.peak
        if self.limit is not None:
            on_power = self.limit.apply(on_power, fast_positive("R", resistance))
        end = time_s + step_size
        duty = self.duty_of(demand_W)
        first, starts = self._index(time_s)
        if not starts and self.held is not None and self.held[0] == first:
            first_duty = self.held[1]
        else:
            first_duty = duty
        last, last_starts = self._index(end)
        if last_starts:
            last -= 1                       # the period starting at the step's end is not in it
        if last <= first:
            on = self._on_time(first, first_duty, time_s, end)
            last, last_duty = first, first_duty
        else:
            on = self._on_time(first, first_duty, time_s, end)
            full = last - first - 1         # whole periods inside the step, all of duty `duty`
            on += full * duty * self.period
            on += self._on_time(last, duty, time_s, end)
            last_duty = duty
        self.held = (last, last_duty)
        self.power = on_power * min(1.0, on / step_size)
        return self.power

    def state(self):
        """JSON-ready state: the period in progress and its duty, the last mean power."""
        return {"held": None if self.held is None else list(self.held), "power": self.power}

    def restore(self, state):
        """Restore a state saved by :meth:`state` (``ValueError`` on a malformed one; no change)."""
        read_entries(state, ("held", "power"), what="PWM state")
        held = state["held"]
        if held is not None:
            if (not isinstance(held, (list, tuple)) or len(held) != 2
                    or isinstance(held[0], bool) or not isinstance(held[0], int)):
                raise ValueError(f"held must be None or [period index, duty], got {held!r:.200}")
            duty = fast_finite("held duty", held[1])
            if not 0.0 <= duty <= 1.0:
                raise ValueError(f"held duty must be in [0, 1], got {duty!r}")
            held = (held[0], duty)
        power = fast_finite("power", state["power"])
        if not 0.0 <= power <= self.peak:
            raise ValueError(f"power must be in [0, peak_W], got {power!r}")
        self.held, self.power = held, power
