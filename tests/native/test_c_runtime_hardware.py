"""The C bench hardware (c_family/runtime: noise, measurement, drive_limit, pwm's limited step)
equals the Python runtime's bit for bit: the noise stream over seeds and sample indices up to
2^40, sensor readings across noise levels and ADC widths (clipping included), the sensed PI
on random walks with its saved state round-tripped mid-walk, the drive limit's caps and the
limited drivers (linear and PWM). Refusals name the same thing in both. No tolerance: the same
integer operations and IEEE operations in the same order."""
import math
import random

import pytest

from sma_fmu.runtime.drive_limit import DriveLimit, LinearDriver
from sma_fmu.runtime.measurement import ResistanceSensor, SensedPIController
from sma_fmu.runtime.noise import standard_normal, word
from sma_fmu.runtime.pwm import PwmDriver

from c_control import normalized
from c_hardware import CLimit, CLimitedPwm, CLinearDriver, CSensedPI, CSensor, load_library


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    return load_library(tmp_path_factory.mktemp("c_hardware"))


def refused(call):
    try:
        call()
    except ValueError as error:
        return str(error)
    return None


def same_refusal(python_call, c_call):
    python, c = refused(python_call), refused(c_call)
    assert python is not None and c is not None, (python, c)
    assert normalized(c).startswith(normalized(python)), (python, c)


def test_noise_equals_python(lib):
    rng = random.Random(1)
    seeds = [0, 1, 2 ** 31 - 1] + [rng.randrange(2 ** 31) for _ in range(20)]
    for seed in seeds:
        for sample in [0, 1, 2 ** 32 + 5, 2 ** 40] + [rng.randrange(4_000_000) for _ in range(200)]:
            assert lib.standard_normal(seed, sample) == standard_normal(seed, sample)
        for index in (1, 2, 3, 2 ** 33):
            assert lib.splitmix64_word(seed, index) == word(seed, index)


@pytest.mark.parametrize("noise, full_scale, bits, seed", [
    (0.0, 0.0, 0, 0), (0.05, 65.536, 16, 1), (0.0, 65.536, 16, 0), (0.3, 0.0, 0, 77),
    (2.0, 10.0, 4, 2 ** 31 - 1), (1e-6, 100.0, 32, 5), (0.05, 1e-300, 32, 3)])
def test_sensor_readings_equal_python(lib, noise, full_scale, bits, seed):
    python, c = ResistanceSensor(noise, full_scale, bits, seed), CSensor(lib, noise, full_scale, bits, seed)
    rng = random.Random(seed)
    for k in range(3000):
        R = rng.choice((rng.uniform(-5, 120), rng.uniform(33, 50), 0.0, 1e300, -1e300))
        assert c.preview(R) == python.preview(R)
        assert c.measure(R) == python.measure(R), (k, R)
        if k % 499 == 0:
            assert c.state() == [float(python.sample)]
            fresh = CSensor(lib, noise, full_scale, bits, seed)
            fresh.restore(c.state())
            c = fresh
    assert c.reading(40.0, 2 ** 40) == python.reading(40.0, 2 ** 40)


def test_sensor_refusals_alike(lib):
    for args in ((-0.1, 1.0, 0, 0), (math.nan, 1.0, 0, 0), (0.1, 1.0, 33, 0), (0.1, 1.0, -1, 0),
                 (0.1, 1.0, 0, -1), (0.1, 1.0, 0, 2 ** 31), (0.1, 0.0, 8, 0), (0.1, math.inf, 0, 0)):
        same_refusal(lambda: ResistanceSensor(*args), lambda: CSensor(lib, *args))
    python, c = ResistanceSensor(0.1, 10.0, 8, 0), CSensor(lib, 0.1, 10.0, 8, 0)
    same_refusal(lambda: python.measure(math.nan), lambda: c.measure(math.nan))
    assert c.state() == [0.0]
    for bad in (-1.0, 0.5, 2.0 ** 54, math.inf):
        same_refusal(lambda: python.restore({"sample": bad if bad != 0.5 else 0.5}),
                     lambda: c.restore([bad]))


@pytest.mark.parametrize("seed", range(4))
def test_sensed_pi_equals_python(lib, seed):
    rng = random.Random(seed)
    Kp, Ki = rng.uniform(0, 5), rng.uniform(0, 20)
    settings = (rng.choice((0.0, 0.05, 0.5)), 65.536, rng.choice((0, 8, 16)), seed)
    python = SensedPIController(Kp, Ki, ResistanceSensor(*settings))
    c = CSensedPI(lib, Kp, Ki, *settings)
    for k in range(5000):
        R, R_ref, P_ff = rng.uniform(30, 50), rng.uniform(30, 50), rng.uniform(-3, 3)
        assert c.preview(R, R_ref, P_ff) == python.preview(R, R_ref, P_ff)
        assert c.sample(R, R_ref, P_ff, 1e-3) == python.sample(R, R_ref, P_ff, 1e-3), k
        assert c.state() == [python.pi.integral, float(python.sensor.sample)]
        if k % 997 == 0:
            fresh = CSensedPI(lib, Kp, Ki, *settings)
            fresh.restore(c.state())
            c = fresh
    for args in ((math.nan, 40, 0, 1e-3), (40, math.inf, 0, 1e-3), (40, 40, math.nan, 1e-3),
                 (40, 40, 0, 0.0)):
        same_refusal(lambda: python.sample(*args), lambda: c.sample(*args))
    assert c.state() == [python.pi.integral, float(python.sensor.sample)]


def test_drive_limits_equal_python(lib):
    rng = random.Random(3)
    for I_max, V_max in ((0.5, 24.0), (0.5, 0.0), (0.0, 24.0), (0.0, 0.0), (1e-3, 1e3)):
        python, c = DriveLimit(I_max, V_max), CLimit(lib, I_max, V_max)
        for _ in range(2000):
            R, P = rng.uniform(1e-3, 1e3), rng.uniform(-5, 50)
            assert c.cap(R) == python.cap(R)
            assert c.apply(P, R) == python.apply(P, R)
    for args in ((-0.5, 0.0), (0.0, -1.0), (math.nan, 0.0), (0.0, math.inf)):
        same_refusal(lambda: DriveLimit(*args), lambda: CLimit(lib, *args))


def test_limited_drivers_equal_python(lib):
    rng = random.Random(4)
    for I_max, V_max in ((0.5, 24.0), (0.3, 0.0), (0.0, 10.0)):
        linear, c_linear = LinearDriver(DriveLimit(I_max, V_max)), CLinearDriver(lib, I_max, V_max)
        pwm = PwmDriver(50.0, 8.0, DriveLimit(I_max, V_max))
        c_pwm = CLimitedPwm(lib, 50.0, 8.0, I_max, V_max)
        for k in range(4000):
            demand, R = rng.uniform(-2, 15), rng.uniform(30, 50)
            t, h = k * 1e-3, 1e-3
            assert c_linear.step(demand, t, h, R) == linear.step(demand, t, h, R)
            assert c_pwm.step(demand, t, h, R) == pwm.step(demand, t, h, R), k
        assert c_linear.state() == [linear.power]
        same_refusal(lambda: linear.step(1.0, 0.0, 1e-3, -2.0),
                     lambda: c_linear.step(1.0, 0.0, 1e-3, -2.0))
        same_refusal(lambda: pwm.step(1.0, 5.0, 1e-3, math.nan),
                     lambda: c_pwm.step(1.0, 5.0, 1e-3, math.nan))


def test_the_files_compile_clean_for_win64(tmp_path):
    from c_hardware import MODULES
    from c_runtime import compile_win64
    objects = compile_win64(MODULES, tmp_path)
    if objects is None:
        pytest.skip("mingw-w64 is not installed")
    assert all(path.is_file() for path in objects)
