"""The batch engine's bench hardware (studies/batch/hardware.py) against the scalar runtime.

The noise sequence is the runtime's stream to the bit (numpy uint64 against Python ints);
batches mixing runs with and without a sensor, with a linear driver under a binding current
limit, a PWM driver with a limited on-power and plain runs agree with the scalar library
path to 1e-10 on every column, and a run's noise depends on its seed alone."""
import dataclasses

import numpy as np
import pytest

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.scenario import DriveSettings, SensorSettings, load_scenario, resolve_scenarios
from sma_fmu.runtime.noise import standard_normal
from sma_fmu.studies.batch import run_batch, unsupported_reason
from sma_fmu.studies.batch.hardware import normal_sequence


def _scenario(name, stop_time_s=4.0, **changes):
    scenario = load_scenario(resolve_scenarios([name])[0])
    return dataclasses.replace(scenario, stop_time_s=stop_time_s, **changes)


@pytest.mark.parametrize("seed", [0, 1, 2 ** 31 - 1, 987654])
def test_the_noise_sequence_is_the_runtimes(seed):
    sequence = normal_sequence(seed, 20_001)
    picks = list(range(50)) + list(range(19_950, 20_001)) + list(range(0, 20_001, 397))
    assert [sequence[k] for k in picks] == [standard_normal(seed, k) for k in picks]


def _bench_variants():
    bench = _scenario("load-step-bench-pi+ff-adaptive")
    drive = bench.drive
    return [
        bench,
        _scenario("heavy-continuous-bench-pi"),
        _scenario("load-step-continuous-bench-pi+ff-adaptive-minor-loop"),
        dataclasses.replace(bench, drive=dataclasses.replace(drive, I_max_A=0.3)),  # binding
        dataclasses.replace(bench, drive=DriveSettings("pwm", 50.0, 8.0, I_max_A=0.3, V_max_V=24.0)),
        dataclasses.replace(bench, sensor=SensorSettings(0.5, 20.0, 6, 9)),   # clips at 20 ohm
        _scenario("load-step-pi+ff-adaptive"),                               # no hardware
        _scenario("setpoints-pwm-pi+ff-adaptive"),
    ]


def test_batches_with_bench_hardware_equal_the_scalar_path():
    scenarios = _bench_variants()
    assert all(unsupported_reason(s) is None for s in scenarios)
    for scenario, run in zip(scenarios, run_batch(scenarios, "timeseries")):
        assert run.path == "batch" and run.error is None
        scalar = run_library(scenario).data
        for name in scalar.dtype.names:
            if scalar.dtype[name] == bool:
                assert np.array_equal(run.data[name], scalar[name]), name
            else:
                assert np.allclose(run.data[name], scalar[name], rtol=0, atol=1e-10,
                                   equal_nan=True), (scenario.name, name)
    limited = run_batch([scenarios[3]], "timeseries")[0].data
    resistance, power = limited["R"][:-1], limited["P"][:-1]
    assert np.all(power <= 0.09 * resistance * (1 + 1e-15))       # P <= I^2 R, I = 0.3 A
    assert np.mean(power >= 0.09 * resistance * (1 - 1e-12)) > 0.2  # and it binds


def test_a_runs_noise_is_its_seeds():
    bench = _scenario("load-step-bench-pi")
    other = dataclasses.replace(bench, sensor=dataclasses.replace(bench.sensor, seed=2))
    runs = run_batch([bench, other, bench], "timeseries")
    assert np.array_equal(runs[0].data["P_fb"], runs[2].data["P_fb"], equal_nan=True)
    assert not np.array_equal(runs[0].data["P_fb"], runs[1].data["P_fb"])


def test_a_study_over_noise_seeds_runs_each_seeds_loop():
    """The study overrides name the sensor and the drive; a batch over five seeds gives each
    seed's scalar run."""
    from sma_fmu.studies import run_many, scenario
    scenarios = [scenario("heavy-bench-pi+ff-adaptive", {"sensor.seed": seed,
                                                         "drive.I_max_A": 0.4,
                                                         "scenario.stop_time_s": 3.0})
                 for seed in range(1, 6)]
    runs = run_many(scenarios, "batch")
    rmses = [run.metrics["overall"]["rmse_ohm"] for run in runs]
    assert len(set(rmses)) == 5
    for item, value in zip(scenarios, rmses):
        assert item.drive.I_max_A == 0.4
        scalar = run_many([item], "library")[0].metrics["overall"]["rmse_ohm"]
        assert value == pytest.approx(scalar, rel=1e-12)
