"""The controller's measurement of the wire's resistance: white noise, then an ADC's quantisation.

    x_k = R_k + sigma z(seed, k)                       z: :func:`~.noise.standard_normal`
    code_k = clip(floor(x_k / q + 1/2), 0, 2^bits - 1),   q = full_scale / 2^bits
    R_meas,k = code_k q                                 (no quantisation when bits = 0)

R_k is the wire's true resistance at sample k (the plant's output), sigma [ohm RMS] the
noise of the sensing chain referred to the resistance, q [ohm] the ADC's step: a 16-bit
converter whose full scale, in resistance, is ``full_scale_ohm``. Rounding to the nearest
code makes the quantisation error uniform in [-q/2, q/2] (variance q^2/12) wherever the
noise or the signal spans several steps; readings beyond the range clip to its ends, as an
ADC's do. Every operation is an IEEE one (a product, a sum, a quotient, ``floor``), so C and
numpy give the same bits (:mod:`.noise` for the noise).

The sample index k is the sensor's own count of measurements (:meth:`ResistanceSensor.measure`
advances it; :meth:`ResistanceSensor.preview` reads sample k without advancing): in the closed
loop it is the step index, one measurement per step. The metrics stay those of the true R:
the sensor changes what the controller sees, not what the wire does.
"""
import math

from .checks import fast_finite, fast_positive, require_finite, require_nonnegative
from .noise import standard_normal
from .pi_control import PIController
from .state_entries import StateError, read_entries, read_number

__all__ = ["MAX_BITS", "MAX_SEED", "ResistanceSensor", "SensedPIController"]

MAX_BITS = 32                 # an ADC wider than this is no ADC (and 2^bits stays exact)
MAX_SEED = 2 ** 31 - 1        # the seed is an FMI 2.0 Integer parameter (32-bit signed)
_MAX_SAMPLE = 2 ** 53         # a sample index a double holds exactly (the C saved state)


def _whole(name, value, low, high):
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise ValueError(f"{name} must be a whole number in [{low}, {high}], got {value!r}")
    return value


class ResistanceSensor:
    """Noise ``noise_ohm_rms`` [ohm RMS] and a ``bits``-bit ADC over 0 ... ``full_scale_ohm``
    [ohm] (``bits`` = 0: no quantisation, ``full_scale_ohm`` unused), noise stream ``seed``.

    ``ideal`` is True without noise and quantisation: the reading is R itself.
    """

    def __init__(self, noise_ohm_rms=0.0, full_scale_ohm=0.0, bits=0, seed=0):
        self.noise = require_nonnegative("noise_ohm_rms", noise_ohm_rms)
        self.bits = _whole("bits", bits, 0, MAX_BITS)
        self.seed = _whole("seed", seed, 0, MAX_SEED)
        full_scale = require_nonnegative("full_scale_ohm", full_scale_ohm)
        if self.bits and not full_scale > 0.0:
            raise ValueError(f"full_scale_ohm must be > 0 with bits = {self.bits}, got "
                             f"{full_scale_ohm!r}")
        self.full_scale = full_scale
        self.step = full_scale / 2.0 ** self.bits if self.bits else 0.0   # q [ohm]
        self.levels = 2.0 ** self.bits                                     # 2^bits codes
        self.top = self.levels - 1.0                                       # the highest
        self.ideal = self.noise == 0.0 and self.bits == 0
        self.sample = 0           # index of the next measurement

    def reading(self, resistance, sample):
        """R_meas [ohm] of the true ``resistance`` [ohm] at sample index ``sample``; no change."""
        value = resistance
        if self.noise:
            value = resistance + self.noise * standard_normal(self.seed, sample)
        if self.bits:   # floor(x/q + 1/2) clipped to [0, top], compared before the floor
            scaled = value / self.step + 0.5
            code = 0.0 if scaled < 1.0 else (self.top if scaled >= self.levels else
                                             float(math.floor(scaled)))
            value = code * self.step
        return value

    def measure(self, resistance):
        """R_meas [ohm] of sample k (then k + 1 is next). A non-finite R raises ``ValueError``."""
        value = self.reading(fast_finite("R", resistance), self.sample)
        self.sample += 1
        return value

    def preview(self, resistance):
        """R_meas [ohm] that :meth:`measure` will give for ``resistance`` [ohm]; no change."""
        return self.reading(require_finite("R", resistance), self.sample)

    def state(self):
        """JSON-ready state: the index of the next sample."""
        return {"sample": self.sample}

    def restore(self, state):
        """Restore a state saved by :meth:`state` (``ValueError`` naming a bad entry; no change)."""
        read_entries(state, ("sample",), what="sensor state")
        sample = state["sample"]
        if isinstance(sample, bool) or not isinstance(sample, int) or not 0 <= sample <= _MAX_SAMPLE:
            raise StateError(f"state entry sample must be a whole number in [0, 2^53], got "
                             f"{sample!r:.80}")
        self.sample = sample


class SensedPIController:
    """The PI (:class:`~.pi_control.PIController`) fed by a :class:`ResistanceSensor`: the
    SmaPiController FMU, whose R input is the wire's true resistance.

    :meth:`sample` returns (u_k [W], Kp e + Ki I [W], R_meas [ohm]) with e = R_meas - R_ref.
    """

    warning = None

    def __init__(self, Kp, Ki, sensor):
        self.pi = PIController(Kp, Ki)
        self.sensor = sensor

    def sample(self, resistance, reference, feedforward, step_size):
        """One step from R [ohm], R_ref [ohm], u_ff [W], h [s], each checked first."""
        resistance = fast_finite("R", resistance)
        reference = fast_finite("R_ref", reference)
        feedforward = fast_finite("P_ff", feedforward)
        step_size = fast_positive("step_size", step_size)
        measured = self.sensor.measure(resistance)
        power, feedback = self.pi.step(measured - reference, feedforward, step_size)
        return power, feedback, measured

    def preview(self, resistance, reference, feedforward):
        """What :meth:`sample` will give (the integral and the sample index unchanged)."""
        measured = self.sensor.preview(resistance)
        return self.pi.preview(measured, reference, feedforward) + (measured,)

    def state(self):
        """JSON-ready hidden state: the integral [ohm.s] and the sensor's next sample."""
        return {**self.pi.state(), **self.sensor.state()}

    def restore(self, state):
        """Restore a state saved by :meth:`state` (``ValueError`` naming a bad entry; no change)."""
        read_entries(state, ("integral", "sample"), what="PI state")
        integral = read_number(state, "integral", unit="ohm.s")
        self.sensor.restore({"sample": state["sample"]})
        self.pi.integral = integral
