"""PWM drive: the driver against independent references, the plant under PWM (return-point
memory holds R, "switch" chatters), the loop's driver hook (Gauss-Seidel and Jacobi), the
batch engine against the library path, the shipped PWM scenarios and bad [drive] tables."""
import dataclasses
from fractions import Fraction

import numpy as np
import pytest

from sma_fmu.cosim.loop import (LibraryCompensator, LibraryDriver, LibraryPlant, run_library,
                                run_loop)
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.scenario import DriveSettings, ScenarioError, load_scenario
from sma_fmu.files.package_data import shipped_file
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.pwm import PwmDriver
from sma_fmu.runtime.reachable_band import reachable_band
from sma_fmu.studies import BatchUnsupported, run_batch
from sma_fmu.studies.batch import unsupported_reason
from sma_fmu.studies.batch.pwm import BatchPwm

BATCH_TOLERANCE = 1e-10      # ohm, degC, m, W, kg, 1: the bound on every column
PWM_SCENARIOS = ("setpoints-pwm-pi+ff-adaptive", "setpoints-pwm-continuous-pi+ff-adaptive")


def _scenario(name):
    return load_scenario(shipped_file("scenarios", f"{name}.toml"))


def _drive(driver, demands, h):
    """The driver's output for ``demands`` [W], one per step of ``h`` [s] from t = 0."""
    return np.array([driver.step(float(u), k * h, h) for k, u in enumerate(demands)])


# --- the driver against independent references ---------------------------------------

def sampled_means(demands, step, frequency, peak, samples=4000):
    """Mean [W] of the PWM wave over each step, from ``samples`` midpoints per step.

    ``step`` and ``frequency`` are exact fractions; a period starting at j / f takes its
    duty from the demand of the step that contains its start (exact rational arithmetic),
    and the wave is sampled with numpy. Returns (means, edges per step).
    """
    n = len(demands)
    periods = int(Fraction(n) * step * frequency) + 2
    owner = [min(n - 1, int(Fraction(j) / frequency / step)) for j in range(periods)]
    duties = np.clip(np.asarray(demands, dtype=float)[owner] / peak, 0.0, 1.0)
    h, f = float(step), float(frequency)
    offsets = (np.arange(samples) + 0.5) / samples
    times = (np.arange(n)[:, None] + offsets[None, :]) * h          # (n, samples)
    position = times * f
    index = np.floor(position).astype(int)
    wave = np.where(position - index < duties[index], peak, 0.0)
    edges = np.array([2 * (int(Fraction(k + 1) * step * frequency)
                           - int(Fraction(k) * step * frequency)) + 2 for k in range(n)])
    return wave.mean(axis=1), edges


@pytest.mark.parametrize("frequency_Hz, step_ms", [(50, 1), (333, 1), (500, 1), (37, 1),
                                                   (2345, 1), (1250, Fraction(7, 10))])
def test_driver_equals_a_sampled_wave(frequency_Hz, step_ms):
    """Demands jump every step (negative, above the peak, in between): each step's output is
    the sampled wave's mean within the sampling error (one sample per edge in the step)."""
    rng = np.random.default_rng(frequency_Hz)
    peak, n, samples = 3.0, 120, 4000
    demands = rng.uniform(-1.0, 4.0, n)
    step = Fraction(step_ms) / 1000
    expected, edges = sampled_means(demands, step, Fraction(frequency_Hz), peak, samples)
    got = _drive(PwmDriver(float(frequency_Hz), peak), demands, float(step))
    np.testing.assert_array_less(np.abs(got - expected), peak * edges / samples + 1e-12)


@pytest.mark.parametrize("duty", [0.0, 0.25, 0.5, 0.8, 1.0])
def test_period_of_two_steps_closed_form(duty):
    """Period = 2 h: even steps get peak min(1, 2 d), odd ones peak max(0, 2 d - 1)."""
    h, peak = 1e-3, 2.0
    got = _drive(PwmDriver(1.0 / (2.0 * h), peak), [duty * peak] * 40, h)
    np.testing.assert_allclose(got[0::2], peak * min(1.0, 2.0 * duty), rtol=0, atol=1e-12)
    np.testing.assert_allclose(got[1::2], peak * max(0.0, 2.0 * duty - 1.0), rtol=0, atol=1e-12)


@pytest.mark.parametrize("frequency_Hz", [100_000.0, 123_457.0])
def test_period_much_shorter_than_the_step_gives_the_mean(frequency_Hz):
    """100 periods or more per step: the demanded power, up to one partial period per end."""
    h, peak, duty = 1e-3, 5.0, 0.37
    got = _drive(PwmDriver(frequency_Hz, peak), [duty * peak] * 50, h)
    bound = 1e-12 if frequency_Hz == 100_000.0 else peak / (frequency_Hz * h)
    np.testing.assert_allclose(got, duty * peak, rtol=0, atol=bound)
    assert frequency_Hz == 100_000.0 or np.ptp(got) > 0.0   # the partial periods do show


def test_period_longer_than_the_step_gives_a_square_wave():
    """10 Hz at 1 ms, duty 0.255: 25 steps on, one step half on, 74 off, every period."""
    h, peak = 1e-3, 4.0
    got = _drive(PwmDriver(10.0, peak), [0.255 * peak] * 300, h)
    period = np.array([peak] * 25 + [0.5 * peak] + [0.0] * 74)
    np.testing.assert_allclose(got, np.tile(period, 3), rtol=0, atol=1e-9)


def test_a_period_keeps_the_duty_set_at_its_start():
    """Period = 4 steps: a demand that changes inside a period waits for the next one."""
    h, peak = 1e-3, 1.0
    demands = [0.75, 0.0, 1.0, 0.0, 0.25, 1.0, 1.0, 1.0, -2.0, 1.0, 1.0, 1.0]
    got = _drive(PwmDriver(250.0, peak), demands, h)
    np.testing.assert_allclose(got, [1, 1, 1, 0, 1, 0, 0, 0, 0, 0, 0, 0], rtol=0, atol=1e-12)


def test_state_restores_mid_period():
    h, rng = 1e-3, np.random.default_rng(3)
    demands = rng.uniform(0.0, 2.0, 60)
    whole = _drive(PwmDriver(37.0, 1.5), demands, h)
    first = PwmDriver(37.0, 1.5)
    _drive(first, demands[:23], h)
    second = PwmDriver(37.0, 1.5)
    second.restore(first.state())
    rest = np.array([second.step(float(u), (23 + k) * h, h) for k, u in enumerate(demands[23:])])
    np.testing.assert_array_equal(rest, whole[23:])


@pytest.mark.parametrize("step_s", [1e-3, 7e-4])
def test_batch_driver_equals_the_runtime_driver(step_s):
    """The vectorised driver, run by run: equal to the scalar one (no tolerance)."""
    rng = np.random.default_rng(11)
    frequencies = np.array([50.0, 333.3, 500.0, 7.0, 1700.0, 123_457.0, 1.0 / (2.0 * step_s)])
    peaks = rng.uniform(0.5, 6.0, frequencies.size)
    demands = rng.uniform(-1.0, 7.0, (400, frequencies.size))
    demands[100:140] = np.nan                    # the batch gives duty 0 (the run is redone)
    batch = BatchPwm(frequencies, peaks, np.arange(frequencies.size))
    got = np.array([batch.step(u, k * step_s, step_s).copy() for k, u in enumerate(demands)])
    for run, (frequency, peak) in enumerate(zip(frequencies, peaks)):
        scalar = PwmDriver(frequency, peak)
        expected = [scalar.step(0.0 if np.isnan(u) else float(u), k * step_s, step_s)
                    for k, u in enumerate(demands[:, run])]
        np.testing.assert_array_equal(got[:, run], expected, err_msg=f"{frequency} Hz")


# --- the plant under PWM: the spec's property ------------------------------------------

def _steady_resistance(params, mode, load, mean_power, pwm, h=1e-3, steps=30_000):
    """R [ohm] over the run of a plant from T_room at ``mean_power`` [W]: constant, or 50 %
    duty at the step rate (peak 2 x mean, frequency 1 / (2 h))."""
    plant = PlantStepper(params, params.T_room, mode, load)
    driver = PwmDriver(1.0 / (2.0 * h), 2.0 * mean_power) if pwm else None
    values = np.empty(steps)
    for k in range(steps):
        power = driver.step(mean_power, k * h, h) if pwm else mean_power
        values[k] = plant.step(power, load, h)[0]
    return values


# mean temperatures [degC] around each load's heating centre (73 degC at 0.05 kg, 83 degC at
# 0.15 kg): a wire heated from T_room is mid-transformation there
@pytest.mark.parametrize("load, mean_temperature", [(0.05, 66.0), (0.05, 70.0), (0.05, 74.0),
                                                    (0.15, 76.0), (0.15, 80.0), (0.15, 84.0)])
def test_pwm_at_the_step_rate_holds_r_in_continuous_mode_and_chatters_in_switch(
        params, load, mean_temperature):
    mean_power = (mean_temperature - params.T_room) / params.K_th     # T = T_room + K_th P
    constant = _steady_resistance(params, "continuous", load, mean_power, pwm=False)[-1]
    band = reachable_band(load, params)
    assert band.hot + 3.0 < constant < band.cold - 1.5                 # mid-transformation
    continuous = _steady_resistance(params, "continuous", load, mean_power, pwm=True)
    assert abs(continuous[-1] - constant) < 0.5
    switch = _steady_resistance(params, "switch", load, mean_power, pwm=True)[-2000:]
    assert switch.max() - switch.min() > 3.0                           # last 2 s


# --- the loop's driver ------------------------------------------------------------------

class RecordingDriver(LibraryDriver):
    """The library driver, recording what it is given and what it gives."""

    def __init__(self, scenario):
        super().__init__(scenario)
        self.calls, self.outputs = [], []

    def step(self, time_s, demand, step_size):
        self.calls.append((time_s, demand, step_size))
        self.outputs.append(super().step(time_s, demand, step_size))
        return self.outputs[-1]


def _short(name, stop_time_s=12.0, **drive):
    scenario = dataclasses.replace(_scenario(name), stop_time_s=stop_time_s)
    if drive:
        scenario = dataclasses.replace(scenario, drive=DriveSettings("pwm", **drive))
    return scenario


def test_library_loop_feeds_the_plant_the_drivers_output():
    """Gauss-Seidel: the driver gets the PI's clamped output u_k at t_k, the plant (P column)
    gets the driver's output in the same step; a fresh driver replays it from the columns."""
    scenario = _short(PWM_SCENARIOS[1])
    driver = RecordingDriver(scenario)
    data = run_loop(scenario, LibraryPlant(scenario), LibraryCompensator(scenario),
                    driver=driver)
    h, n = scenario.step_s, scenario.steps
    demand = np.maximum(0.0, data["P_ff"][:-1] + data["P_fb"][:-1])
    calls = np.array(driver.calls)
    np.testing.assert_array_equal(calls[:, 0], data["t"][:-1])
    np.testing.assert_array_equal(calls[:, 1], demand)
    np.testing.assert_array_equal(data["P"][:-1], driver.outputs)
    replay = _drive(PwmDriver(50.0, 4.0), demand, h)
    np.testing.assert_array_equal(data["P"][:-1], replay)
    assert set(np.unique(data["P"][:-1])) - {0.0, 4.0}      # steps with an edge
    np.testing.assert_array_equal(run_library(scenario).data["R"], data["R"])   # the default
    assert len(data) == n + 1


def test_jacobi_driver_gets_the_held_demand_and_the_plant_the_held_drive():
    """Jacobi (an SSP host): the driver gets u_k-1 (u_0 at k = 0), the plant the driver's
    output of the step before (at k = 0 its output after initialization, 0 W)."""
    scenario = dataclasses.replace(_short("load-step-pi", 3.0),
                                   drive=DriveSettings("pwm", 250.0, 3.0))
    driver = RecordingDriver(scenario)
    data = run_loop(scenario, LibraryPlant(scenario), None, "jacobi", driver=driver)
    u = np.maximum(0.0, data["P_fb"][:-1])                    # pi: P_ff = 0
    demands = np.array([call[1] for call in driver.calls])
    np.testing.assert_array_equal(demands, np.concatenate([u[:1], u[:-1]]))
    replay = _drive(PwmDriver(250.0, 3.0), demands, scenario.step_s)
    assert data["P"][0] == 0.0
    np.testing.assert_array_equal(data["P"][1:-1], replay[:-1])
    gauss_seidel = run_library(scenario).data
    assert np.max(np.abs(gauss_seidel["R"] - data["R"])) > 1e-3


# --- the batch engine -------------------------------------------------------------------

def _assert_same_series(batch_data, scalar_data, label):
    for field in scalar_data.dtype.names:
        if field == "saturated":
            assert np.array_equal(batch_data[field], scalar_data[field]), (label, field)
        else:
            np.testing.assert_allclose(batch_data[field], scalar_data[field], rtol=0,
                                       atol=BATCH_TOLERANCE, equal_nan=True,
                                       err_msg=f"{label} {field}")


def _pwm_set():
    """The shipped PWM scenarios (load steps at 10 s and 20 s) and variants of other
    frequencies, peaks and controllers, with two power-drive runs: some columns of the batch
    are switched, some not."""
    switch, continuous = (_scenario(name) for name in PWM_SCENARIOS)
    pwm = lambda s, f, p: dataclasses.replace(s, drive=DriveSettings("pwm", f, p))  # noqa: E731
    return [switch, continuous,
            pwm(_scenario("load-step-pi"), 333.3, 6.0),
            pwm(_scenario("heavy-continuous-pi+ff-fixed"), 1700.0, 5.0),
            pwm(continuous, 7.0, 5.0),
            pwm(_scenario("load-step-continuous-pi+ff-adaptive-minor-loop"), 500.0, 8.0),
            _scenario("load-step-pi+ff-fixed"), _scenario("heavy-continuous-pi")]


@pytest.fixture(scope="module")
def library_runs():
    return [run_library(scenario).data for scenario in _pwm_set()]


@pytest.mark.parametrize("only_pwm", [False, True])
def test_batch_equals_the_library_path_with_pwm(library_runs, only_pwm):
    scenarios, expected = _pwm_set(), library_runs
    if only_pwm:                           # every column switched
        scenarios, expected = scenarios[:6], expected[:6]
    results = run_batch(scenarios, record="timeseries")
    for scenario, result, scalar in zip(scenarios, results, expected):
        label = f"{scenario.name} {scenario.hysteresis_mode} {scenario.drive}"
        assert result.path == "batch", label
        _assert_same_series(result.data, scalar, label)


def test_batch_metrics_with_pwm_equal_scenario_metrics(library_runs):
    scenarios = _pwm_set()
    for scenario, result, scalar in zip(scenarios, run_batch(scenarios), library_runs):
        expected = scenario_metrics(scalar, scenario)
        assert result.metrics["clamped_fraction"] == expected["clamped_fraction"]
        assert result.metrics["overall"]["rmse_ohm"] == pytest.approx(
            expected["overall"]["rmse_ohm"], rel=0, abs=BATCH_TOLERANCE)


def test_batch_knows_the_drive():
    pwm = _short(PWM_SCENARIOS[0], 1.0)
    assert unsupported_reason(pwm) is None
    other = dataclasses.replace(pwm, drive=DriveSettings("current", 50.0, 0.2))
    assert unsupported_reason(other) == (f"{pwm.name}: drive kind 'current' is not "
                                         "implemented in the batch engine")
    with pytest.raises(BatchUnsupported, match="drive kind 'current'"):
        run_batch([pwm, other])
    extended = dataclasses.make_dataclass("Extended", [("dead_time_s", float, 0.0)],
                                          bases=(DriveSettings,), frozen=True)
    dead = dataclasses.replace(pwm, drive=extended("pwm", 50.0, 4.0, 1e-5))
    assert "drive option dead_time_s = 1e-05" in unsupported_reason(dead)
    wider = dataclasses.make_dataclass("Wider", [("sensor_noise_ohm", float, 0.0)],
                                       bases=(type(pwm),), frozen=True)
    noisy = wider(**{f.name: getattr(pwm, f.name) for f in dataclasses.fields(pwm)})
    assert "sensor_noise_ohm" in unsupported_reason(noisy)


# --- the shipped PWM scenarios and the [drive] table ------------------------------------

@pytest.mark.parametrize("name, mode", zip(PWM_SCENARIOS, ("switch", "continuous")))
def test_shipped_pwm_scenarios(params, name, mode):
    scenario = _scenario(name)
    assert (scenario.drive, scenario.hysteresis_mode) == (DriveSettings("pwm", 50.0, 4.0), mode)
    assert scenario.controller.kind == "pi+ff-adaptive" and scenario.steps == 30_000
    assert params.T_room + params.K_th * scenario.drive.peak_W > 105.0
    times = np.arange(scenario.steps + 1) * scenario.step_s
    for start, end, load in scenario.load.segments(scenario.stop_time_s):
        band = reachable_band(load, params)
        inside = [scenario.reference.value(t) for t in times if start <= t < end]
        assert band.hot + 3.0 < min(inside) and max(inside) < band.cold - 3.0
    levels = {scenario.reference.value(t) for t in times}
    assert {44.0, 38.0, 42.0, 46.0, 40.0, 45.0} <= levels


def _scenario_file(tmp_path, drive):
    path = tmp_path / "pwm.toml"
    base = shipped_file("scenarios", "load-step-pi.toml").read_text()
    path.write_text(base + "\n[drive]\n" + drive)
    return path


@pytest.mark.parametrize("drive, message", [
    ('kind = "pulse"\n', r"\[drive\] kind must be one of power, pwm, got 'pulse'"),
    ('kind = "pwm"\npeak_W = 4.0\n', r"\[drive\] missing key frequency_Hz"),
    ('kind = "pwm"\nfrequency_Hz = 50.0\n', r"\[drive\] missing key peak_W"),
    ('kind = "pwm"\nfrequency_Hz = -50.0\npeak_W = 4.0\n',
     r"\[drive\] frequency_Hz must be > 0, got -50.0"),
    ('kind = "pwm"\nfrequency_Hz = 50.0\npeak_W = 0\n', r"\[drive\] peak_W must be > 0, got 0"),
    ('kind = "pwm"\nfrequency_Hz = "50 Hz"\npeak_W = 4.0\n',
     r"\[drive\] frequency_Hz must be a finite number, got '50 Hz'"),
    ('kind = "power"\nfrequency_Hz = 50.0\n',
     r"\[drive\] frequency_Hz only apply to kind = 'pwm'"),
    ('kind = "pwm"\nfrequency_Hz = 50.0\npeak_W = 4.0\nduty = 0.5\n',
     r"\[drive\] unknown key\(s\) duty"),
])
def test_bad_drive_names_file_and_key(tmp_path, drive, message):
    path = _scenario_file(tmp_path, drive)
    with pytest.raises(ScenarioError, match=message) as raised:
        load_scenario(path)
    assert str(path) in str(raised.value)


def test_drive_defaults_to_power(tmp_path):
    assert _scenario("load-step-pi").drive == DriveSettings()
    assert load_scenario(_scenario_file(tmp_path, 'kind = "power"\n')).drive == DriveSettings()
