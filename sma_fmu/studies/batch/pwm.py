"""PWM drivers of a batch (:class:`~sma_fmu.runtime.pwm.PwmDriver`), advanced in lock-step.

A second implementation of the scalar driver, operation by operation, so the two agree to
rounding (tests/runtime/test_pwm.py binds them): per run a frequency, a peak power, the index of
the period in progress and its duty. In step [t, t + h) with the demand u held:

    duty      = clip(u / peak, 0, 1)                     (0 for u <= 0, also for NaN)
    (j, s)    = the period containing t, s: it starts there (within PERIOD_TOLERANCE)
    duty_j    = the held duty if not s and j is the held period, else duty
    (l, s')   = the period containing t + h; l - 1 when it starts at t + h
    on        = on-time of period j at duty_j in [t, t + h)
                + (l - j - 1) duty / f + on-time of period l at duty   (only when l > j)
    P_in      = peak min(1, on / h)

where the on-time of period i at duty d in [a, b) is max(0, min(i/f + d/f, b) - max(i/f, a)).
Where the scalar code branches, the batch selects with ``numpy.where``. Runs whose drive is
"power" are not in the driver; the batch passes their demand on.
"""
import numpy as np

from sma_fmu.runtime.pwm import PERIOD_TOLERANCE

__all__ = ["BatchPwm"]


def _period_index(time_s, frequency):
    """(index, starts) per run: :meth:`PwmDriver._index` of ``time_s`` [s] at ``frequency`` [Hz]."""
    position = time_s * frequency
    nearest = np.round(position)                   # half to even, as Python's round
    starts = np.abs(position - nearest) <= PERIOD_TOLERANCE * np.maximum(1.0, np.abs(position))
    return np.where(starts, nearest, np.floor(position)), starts


def _on_time(index, duty, period, start, end):
    """On-time [s] of period ``index`` with ``duty`` inside [start, end), per run."""
    begin = index * period
    return np.maximum(0.0, np.minimum(begin + duty * period, end) - np.maximum(begin, start))


class BatchPwm:
    """The PWM drivers of the runs ``runs`` (an index array) of a batch.

    Parameters
    ----------
    frequency_Hz, peak_W : numpy.ndarray
        Each run's switching frequency [Hz] and on-power [W] (> 0).
    runs : numpy.ndarray
        The batch's columns these drivers serve (the runs with a PWM drive).
    """

    def __init__(self, frequency_Hz, peak_W, runs):
        self.runs = np.asarray(runs)
        self.frequency = np.asarray(frequency_Hz, dtype=float)
        self.peak = np.asarray(peak_W, dtype=float)
        self.period = 1.0 / self.frequency
        self.held_index = np.full(self.runs.size, np.nan)   # no period held yet
        self.held_duty = np.zeros(self.runs.size)

    def step(self, demand, time_s, step_size, on_power=None):
        """Mean power [W] of each run's wave over [time_s, time_s + step_size) for ``demand`` [W].

        ``demand``: one entry per run of :attr:`runs`; ``time_s`` [s] and ``step_size`` [s]
        are the batch's, as floats. ``on_power`` [W] per run: the wave's on-power under a
        drive limit (None: ``peak_W``). Non-finite demands give duty 0 here (the scalar
        driver raises; the batch reruns such runs on the scalar path).
        """
        frequency, period, peak = self.frequency, self.period, self.peak
        end = time_s + step_size
        ratio = demand / peak
        duty = np.where(ratio > 0.0, np.where(ratio > 1.0, 1.0, ratio), 0.0)
        first, starts = _period_index(time_s, frequency)
        first_duty = np.where(~starts & (self.held_index == first), self.held_duty, duty)
        last, last_starts = _period_index(end, frequency)
        last = np.where(last_starts, last - 1.0, last)
        several = last > first
        on = _on_time(first, first_duty, period, time_s, end)
        if several.any():
            full = last - first - 1.0                     # whole periods inside the step
            more = on + full * duty * period
            more = more + _on_time(last, duty, period, time_s, end)
            on = np.where(several, more, on)
            self.held_index = np.where(several, last, first)
            self.held_duty = np.where(several, duty, first_duty)
        else:
            self.held_index, self.held_duty = first, first_duty
        return (peak if on_power is None else on_power) * np.minimum(1.0, on / step_size)
