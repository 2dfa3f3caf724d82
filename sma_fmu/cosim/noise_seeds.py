"""A noisy scenario's RMSE over several noise streams: one run is one draw of the noise.

With a ``[sensor]`` whose noise is not 0, a run's RMSE depends on the stream; the figure a
table quotes is the median over :data:`NOISE_SEEDS` streams, the scenario's seed and the next
ones (seed, seed + 1, ...), each run on the library path.
"""
import dataclasses
import statistics

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.runtime.measurement import MAX_SEED

__all__ = ["NOISE_SEEDS", "with_seed", "noise_seed_rmse"]

NOISE_SEEDS = 5


def with_seed(scenario, seed):
    """``scenario`` with its sensor's noise stream ``seed`` (taken mod 2^31: past the last
    stream, the count goes on from 0)."""
    return dataclasses.replace(scenario, sensor=dataclasses.replace(
        scenario.sensor, seed=seed % (MAX_SEED + 1)))


def noise_seed_rmse(scenario, seeds=NOISE_SEEDS):
    """(RMSE [ohm], [RMSE of each stream] or None): the median over ``seeds`` streams for a
    noisy sensor, else the one run's RMSE (and None)."""
    sensor = scenario.sensor
    if not sensor.noise_ohm_rms:
        return scenario_metrics(run_library(scenario).data, scenario)["overall"]["rmse_ohm"], None
    values = []
    for seed in range(sensor.seed, sensor.seed + seeds):
        run = with_seed(scenario, seed)
        values.append(scenario_metrics(run_library(run).data, run)["overall"]["rmse_ohm"])
    return statistics.median(values), values
