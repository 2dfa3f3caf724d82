"""The bench hardware blocks of the runtime against independent references.

- SplitMix64: the published first outputs of seed 0 and a plain sequential generator
  (state += GAMMA; mix) written here from the algorithm.
- The Irwin-Hall normal: its lanes summed one by one here; its moments against the closed
  forms (mean 0, variance 1 - 2^-32, fourth moment 3 - 6/(5 n) = 2.9) and its distribution
  against the Irwin-Hall CDF (a Kolmogorov-Smirnov test, scipy).
- The ADC: the quantisation error uniform in [-q/2, q/2] (variance q^2/12), the clip at the
  range's ends, noise plus quantisation at variance sigma^2 + q^2/12 (Sheppard).
- The drive limit: P = I^2 R and V^2 / R by hand, the crossover at R = V/I, the PWM
  on-power cut.
"""
import math
import re

import numpy as np
import pytest
from scipy import stats
from scipy.special import comb

from sma_fmu.runtime.drive_limit import DriveLimit, LinearDriver
from sma_fmu.runtime.measurement import ResistanceSensor, SensedPIController
from sma_fmu.runtime.noise import GAMMA, MASK, mix, standard_normal, word
from sma_fmu.runtime.pi_control import PIController
from sma_fmu.runtime.pwm import PwmDriver


def sequential_splitmix64(seed, count):
    """The reference generator, one output after another (Steele, Lea, Flood 2014)."""
    state, out = seed, []
    for _ in range(count):
        state = (state + GAMMA) & MASK
        z = state
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
        out.append(z ^ (z >> 31))
    return out


def test_splitmix64_published_outputs_and_the_sequential_generator():
    assert [word(0, i) for i in (1, 2, 3)] == [0xE220A8397B1DCDAF, 0x6E789E6AA1B965F4,
                                               0x06C45D188009454F]
    for seed in (0, 1, 12345, 2 ** 31 - 1):
        assert [word(seed, i) for i in range(1, 41)] == sequential_splitmix64(seed, 40)
    assert mix(0) == 0


def _lanes_one_by_one(seed, sample):
    words = sequential_splitmix64(seed, 3 * sample + 3)[3 * sample:]
    return sum((w >> shift) & 0xFFFF for w in words for shift in (0, 16, 32, 48))


def test_standard_normal_is_the_sum_of_twelve_uniforms_minus_six():
    for seed in (0, 7, 2 ** 31 - 1):
        for sample in (0, 1, 2, 999, 123456):
            total = _lanes_one_by_one(seed, sample)
            uniforms = (total + 12 * 0.5) / 65536.0         # sum of (b_i + 1/2) / 2^16
            assert standard_normal(seed, sample) == uniforms - 6.0


def irwin_hall_cdf(x, n=12):
    """CDF of the sum of n uniforms on (0, 1) at x (closed form)."""
    x = np.asarray(x, dtype=float)
    total = np.zeros_like(x)
    for k in range(n + 1):
        total += (-1) ** k * comb(n, k) * np.clip(x - k, 0.0, None) ** n
    return total / math.factorial(n)


@pytest.fixture(scope="module")
def samples():
    return np.array([standard_normal(3, k) for k in range(100_000)])


def test_noise_moments_against_the_closed_forms(samples):
    n = samples.size
    assert abs(samples.mean()) < 4.0 / math.sqrt(n)                      # 4 sigma of the mean
    variance = samples.var()
    assert abs(variance - (1.0 - 2.0 ** -32)) < 4.0 * math.sqrt(1.9 / n)  # (mu4 - 1)/n
    fourth = np.mean(samples ** 4)
    assert abs(fourth - 2.9) < 0.1                                         # 3 - 6/(5 * 12)
    assert np.abs(samples).max() < 6.0
    # steps of 1/65536: every value is a whole number of them
    assert np.all(samples * 65536.0 == np.round(samples * 65536.0))


def test_noise_follows_the_irwin_hall_distribution(samples):
    result = stats.kstest(samples + 6.0, irwin_hall_cdf)
    assert result.pvalue > 1e-3
    # and is told apart from uniform noise of the same variance (the test has power)
    assert stats.kstest(samples + 6.0, lambda x: np.clip((x - 6.0) / (2 * 3 ** 0.5) + 0.5,
                                                         0, 1)).pvalue < 1e-10


def test_streams_differ_by_seed_and_are_uncorrelated():
    a = np.array([standard_normal(1, k) for k in range(20_000)])
    b = np.array([standard_normal(2, k) for k in range(20_000)])
    assert abs(np.corrcoef(a, b)[0, 1]) < 4.0 / math.sqrt(a.size)
    assert abs(np.corrcoef(a[:-1], a[1:])[0, 1]) < 4.0 / math.sqrt(a.size)   # white


def test_an_ideal_sensor_reads_r_itself():
    sensor = ResistanceSensor()
    assert sensor.ideal
    for value in (0.0, 33.3, 47.123456789):
        assert sensor.measure(value) == value


def test_quantisation_error_is_uniform_within_half_a_step():
    sensor = ResistanceSensor(0.0, 65.536, 12, 0)             # q = 16 mohm
    q = 65.536 / 4096
    rng = np.random.default_rng(5)
    values = rng.uniform(30.0, 50.0, 50_000)
    readings = np.array([sensor.reading(float(v), 0) for v in values])
    errors = readings - values
    assert np.abs(errors).max() <= q / 2 * (1 + 1e-12)
    assert np.allclose(readings / q, np.round(readings / q), rtol=0, atol=1e-9)
    assert abs(errors.mean()) < 4 * q / math.sqrt(12 * values.size)
    assert errors.var() == pytest.approx(q * q / 12, rel=0.03)


def test_readings_clip_at_the_ends_of_the_range():
    sensor = ResistanceSensor(0.0, 10.0, 4, 0)                 # 16 codes of 0.625 ohm
    assert sensor.reading(50.0, 0) == 15 * 0.625
    assert sensor.reading(9.99, 0) == 15 * 0.625
    assert sensor.reading(-3.0, 0) == 0.0
    assert sensor.reading(0.3, 0) == 0.0 and sensor.reading(0.32, 0) == 0.625


def test_noise_and_quantisation_add_as_sheppard_says():
    sigma, q = 0.05, 65.536 / 2 ** 13
    sensor = ResistanceSensor(sigma, 65.536, 13, 11)
    errors = np.array([sensor.measure(40.0) for _ in range(60_000)]) - 40.0
    expected = sigma ** 2 * (1 - 2.0 ** -32) + q * q / 12
    assert errors.var() == pytest.approx(expected, rel=0.03)
    assert abs(errors.mean()) < 4 * math.sqrt(expected / errors.size) + q / 8


def test_measure_advances_preview_does_not_and_the_state_round_trips():
    sensor = ResistanceSensor(0.05, 65.536, 16, 9)
    first = sensor.preview(40.0)
    assert sensor.measure(40.0) == first and sensor.sample == 1
    saved = sensor.state()
    values = [sensor.measure(40.0) for _ in range(5)]
    sensor.restore(saved)
    assert [sensor.measure(40.0) for _ in range(5)] == values
    for bad in ({"sample": -1}, {"sample": 1.5}, {"sample": True}, {}, {"sample": 2 ** 54}):
        with pytest.raises(ValueError):
            sensor.restore(bad)


@pytest.mark.parametrize("kwargs, message", [
    ({"noise_ohm_rms": -0.1}, "noise_ohm_rms must be >= 0"),
    ({"bits": 33}, "bits must be a whole number in [0, 32]"),
    ({"seed": -1}, "seed must be a whole number in [0, 2147483647]"),
    ({"bits": 8, "full_scale_ohm": 0.0}, "full_scale_ohm must be > 0 with bits = 8"),
    ({"full_scale_ohm": math.inf}, "full_scale_ohm must be finite")])
def test_sensor_refusals(kwargs, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        ResistanceSensor(**kwargs)


def test_the_sensed_pi_is_the_pi_on_the_reading():
    sensor = ResistanceSensor(0.2, 65.536, 10, 4)
    sensed, plain = SensedPIController(2.0, 5.0, sensor), PIController(2.0, 5.0)
    reference = ResistanceSensor(0.2, 65.536, 10, 4)
    for k in range(200):
        R = 40.0 + math.sin(k / 10)
        reading = reference.measure(R)
        assert sensed.preview(R, 41.0, 0.5)[2] == reading
        assert sensed.sample(R, 41.0, 0.5, 1e-3) == plain.sample(reading, 41.0, 0.5, 1e-3) + (reading,)
    state = sensed.state()
    assert state == {"integral": plain.integral, "sample": 200}


def test_the_current_and_voltage_limits_by_hand():
    limit = DriveLimit(0.5, 24.0)
    assert limit.cap(40.0) == 0.5 ** 2 * 40.0 == 10.0          # I^2 R below V/I = 48 ohm
    assert limit.cap(60.0) == 24.0 ** 2 / 60.0 == 9.6         # V^2 / R above it
    assert limit.cap(48.0) == 12.0                            # both at the crossover
    assert limit.apply(7.0, 40.0) == 7.0 and limit.apply(11.0, 40.0) == 10.0
    assert limit.apply(-1.0, 40.0) == -1.0                    # the plant applies it as 0 W
    assert DriveLimit(0.5).cap(1e3) == 250.0                  # no voltage limit
    assert DriveLimit(0.0, 10.0).cap(1.0) == 100.0            # no current limit
    assert not DriveLimit().limited and DriveLimit().cap(40.0) == math.inf
    with pytest.raises(ValueError, match="I_max_A must be >= 0"):
        DriveLimit(-0.5)


def test_the_linear_driver_and_the_limited_pwm():
    linear = LinearDriver(DriveLimit(0.5))
    assert linear.step(20.0, 0.0, 1e-3, 40.0) == 10.0 and linear.power == 10.0
    assert linear.step(3.0, 0.0, 1e-3, 40.0) == 3.0
    with pytest.raises(ValueError, match="R must be > 0"):
        linear.step(3.0, 0.0, 1e-3, 0.0)
    assert LinearDriver(DriveLimit()).step(20.0, 0.0, 1e-3, math.nan) == 20.0   # R unused
    # PWM at 50 Hz over 1-ms steps: a full duty gives the on-power, cut to I^2 R = 10 W
    pwm = PwmDriver(50.0, 12.0, DriveLimit(0.5))
    assert pwm.step(12.0, 0.0, 1e-3, 40.0) == 10.0
    assert PwmDriver(50.0, 12.0).step(12.0, 0.0, 1e-3) == 12.0
    half = PwmDriver(50.0, 12.0, DriveLimit(0.5))
    powers = [half.step(6.0, k * 1e-3, 1e-3, 40.0) for k in range(20)]   # duty 1/2 of peak
    assert np.mean(powers) == pytest.approx(5.0, rel=1e-12)              # 10 W on, half the time
