"""The bench hardware of a batch: the controllers' resistance sensors and the drivers' limits.

Vectorised twins of :class:`~sma_fmu.runtime.measurement.ResistanceSensor` and
:class:`~sma_fmu.runtime.drive_limit.DriveLimit`, operation by operation:

- **noise**: z(seed, k) is a function of the seed and the step only, so each seed's whole
  sequence is computed once per batch (:func:`normal_sequence`: SplitMix64 in numpy's
  ``uint64``, which wraps mod 2^64 as C does; the same integers and the one exact division
  as :func:`~sma_fmu.runtime.noise.standard_normal`, so the same bits). Runs that share a
  seed (a tuning's candidates) share the sequence.
- **sensor**: x = R + sigma z, then q floor(x / q + 1/2) clipped to [0, 2^bits - 1] codes,
  on the runs with a ``[sensor]`` only; the others read R itself.
- **limit**: P_cap = min((I_max^2) R, (V_max^2) / R) with +inf for a limit not set; a
  linear driver's power is min(u, P_cap), a PWM driver's on-power min(peak_W, P_cap).

Every product, quotient and ``floor`` is an IEEE operation, so a run's readings are those of
the scalar path to the bit wherever its R is (the plants agree with the scalar ones to
rounding: tests/studies/test_batch_hardware.py).
"""
import numpy as np

from sma_fmu.runtime.noise import GAMMA, LANE_OFFSET

__all__ = ["normal_sequence", "BatchSensors", "BatchLimits"]

_MIX1, _MIX2 = np.uint64(0xBF58476D1CE4E5B9), np.uint64(0x94D049BB133111EB)
_PAIRS = np.uint64(0x0000FFFF0000FFFF)


def _mix(z):
    """SplitMix64's output function of a uint64 array."""
    z = (z ^ (z >> np.uint64(30))) * _MIX1
    z = (z ^ (z >> np.uint64(27))) * _MIX2
    return z ^ (z >> np.uint64(31))


def normal_sequence(seed, count):
    """z(seed, k) [1] for k = 0 ... count - 1 (:func:`~sma_fmu.runtime.noise.standard_normal`)."""
    gamma = np.uint64(GAMMA)
    samples = np.arange(count, dtype=np.uint64)
    with np.errstate(over="ignore"):
        state = np.uint64(seed) + samples * (np.uint64(3) * gamma)
        lanes = np.zeros(count, dtype=np.uint64)
        for word in (1, 2, 3):
            z = _mix(state + np.uint64(word) * gamma)
            lanes += (z & _PAIRS) + ((z >> np.uint64(16)) & _PAIRS)
    total = (lanes & np.uint64(0xFFFFFFFF)) + (lanes >> np.uint64(32))
    return (total.astype(np.int64) - LANE_OFFSET).astype(np.float64) / 65536.0


class BatchSensors:
    """The sensors of the runs of ``scenarios`` that have a ``[sensor]``, over ``steps`` + 1
    samples. :attr:`runs` (ascending) are those runs; the others read R itself."""

    def __init__(self, scenarios, steps):
        settings = [(run, s.sensor) for run, s in enumerate(scenarios) if not s.sensor.ideal]
        self.runs = np.array([run for run, _ in settings], dtype=int)
        seeds = sorted({sensor.seed for _, sensor in settings if sensor.noise_ohm_rms})
        self._sequences = np.column_stack([normal_sequence(seed, steps + 1) for seed in seeds]) \
            if seeds else np.zeros((steps + 1, 0))
        column = {seed: i for i, seed in enumerate(seeds)}
        self._column = np.array([column.get(sensor.seed, 0) for _, sensor in settings], dtype=int)
        self.noise = np.array([sensor.noise_ohm_rms for _, sensor in settings], dtype=float)
        bits = np.array([sensor.bits for _, sensor in settings], dtype=int)
        self.levels = np.ldexp(1.0, bits)
        full_scale = np.array([sensor.full_scale_ohm for _, sensor in settings], dtype=float)
        self.quantised = bits > 0
        self.step = np.where(self.quantised, full_scale / self.levels, 1.0)   # q [ohm]
        self.top = self.levels - 1.0

    def read(self, resistance, k):
        """R_meas [ohm] of every run at step ``k`` from the true ``resistance`` (N,)."""
        if not self.runs.size:
            return resistance
        measured = resistance.copy()
        value = resistance[self.runs]
        noisy = self.noise != 0.0
        if noisy.any():
            z = self._sequences[k, self._column] if self._sequences.shape[1] else 0.0
            value = np.where(noisy, value + self.noise * z, value)
        if self.quantised.any():
            scaled = value / self.step + 0.5
            code = np.where(scaled < 1.0, 0.0, np.where(scaled >= self.levels, self.top,
                                                        np.floor(scaled)))
            value = np.where(self.quantised, code * self.step, value)
        measured[self.runs] = value
        return measured


class BatchLimits:
    """The current and voltage limits of the runs of ``scenarios`` whose drive has one."""

    def __init__(self, scenarios):
        drives = [(run, s.drive) for run, s in enumerate(scenarios) if s.drive.limited]
        self.runs = np.array([run for run, _ in drives], dtype=int)
        current = np.array([d.I_max_A for _, d in drives], dtype=float)
        voltage = np.array([d.V_max_V for _, d in drives], dtype=float)
        self.current_squared = np.where(current != 0.0, current * current, np.inf)   # [A^2]
        self.voltage_squared = np.where(voltage != 0.0, voltage * voltage, np.inf)   # [V^2]
        self.linear = np.array([not d.pwm for _, d in drives], dtype=bool)

    def caps(self, resistance):
        """P_cap [W] of each limited run at the wires' ``resistance`` (N,) [ohm]."""
        wire = resistance[self.runs]
        by_current = self.current_squared * wire
        by_voltage = self.voltage_squared / wire
        return np.where(by_current <= by_voltage, by_current, by_voltage)
