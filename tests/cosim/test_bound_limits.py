"""The tracking bound under a driver's current and voltage limit (P <= I^2 R, P <= V^2 / R).

Independent references: a constant cap above every I^2 R the wire reaches gives a lower
bound no higher, a constant cap below every one a bound no lower (a larger power set can only
lower the optimum); the benchmark's replayed powers satisfy P_k <= I^2 R_k checked by hand;
a limit far above any power used gives the unlimited bound; `sma-fmu bound` reads the limit
from the scenario's [drive] and puts the median of five noise seeds beside it.
"""
import dataclasses
import json
import statistics

import numpy as np
import pytest

from sma_fmu.analysis.inverse_tracker import track
from sma_fmu.analysis.power_limit import PowerLimit
from sma_fmu.analysis.switch_dp import node_path, replay_path
from sma_fmu.analysis.tracking_bound import tracking_bound
from sma_fmu.analysis.tracking_problem import TemperatureGrid, TrackingProblem
from sma_fmu.cli import main
from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.noise_seeds import with_seed
from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios
from sma_fmu.runtime.reachable_band import reachable_band

CURRENT = 0.45    # [A]: binds (I^2 R = 6.9-9.7 W over the wire's band; the paper's loop heats at up to ~8 W)


def _short(name, stop=4.5):
    scenario = load_scenario(resolve_scenarios([name])[0])
    return dataclasses.replace(scenario, stop_time_s=stop)


@pytest.fixture(scope="module")
def switch_scenario():
    return _short("load-step-bench-pi+ff-adaptive")


def _band_extremes(scenario):
    loads = set(scenario.load.values)
    bands = [reachable_band(load, scenario.params) for load in loads]
    return min(b.hot for b in bands), max(b.cold for b in bands)


def test_power_limit_by_hand():
    limit = PowerLimit(10.0, 0.5, 24.0)
    assert limit.at(40.0) == 10.0 and limit.at(30.0) == 7.5 and limit.at(64.0) == 9.0
    assert limit.most(30.0, 40.0) == 10.0 and limit.least(30.0, 40.0) == 7.5
    assert PowerLimit().describe() == "unlimited" and not PowerLimit(5.0).by_resistance
    assert PowerLimit(None, 0.5).describe() == "I <= 0.5 A"


def test_the_switch_bound_lies_between_the_constant_caps(switch_scenario):
    scenario = switch_scenario
    hot, cold = _band_extremes(scenario)
    limited = tracking_bound(scenario, current_A=CURRENT, voltage_V=0.0)
    above = tracking_bound(scenario, power_cap=CURRENT ** 2 * cold, current_A=0.0, voltage_V=0.0)
    below = tracking_bound(scenario, power_cap=CURRENT ** 2 * hot, current_A=0.0, voltage_V=0.0)
    assert above.lower_bound_ohm <= limited.lower_bound_ohm <= below.lower_bound_ohm
    assert above.lower_bound_ohm < below.lower_bound_ohm            # the test can tell them apart
    assert limited.lower_bound_ohm <= limited.achievable.rmse_ohm
    assert (limited.current_limit_A, limited.voltage_limit_V) == (CURRENT, None)
    # a limit far above what any move needs changes nothing
    loose = tracking_bound(scenario, current_A=100.0, voltage_V=0.0)
    free = tracking_bound(scenario, current_A=0.0, voltage_V=0.0)
    assert loose.lower_bound_ohm == pytest.approx(free.lower_bound_ohm, abs=1e-9)


def test_the_benchmarks_respect_the_limit_at_the_plants_resistance(switch_scenario):
    limit = PowerLimit(None, CURRENT, 24.0)
    problem = TrackingProblem.from_scenario(switch_scenario)
    _, temperatures, rows = node_path(problem, TemperatureGrid.for_problem(problem), limit)
    continuous = TrackingProblem.from_scenario(switch_scenario, mode="continuous")
    for case, (powers, resistances) in (
            ("switch path", replay_path(problem, temperatures, rows, limit)),
            ("one-step inverse", track(continuous, 0.0, limit))):
        caps = np.minimum(CURRENT ** 2 * resistances[:-1], 24.0 ** 2 / resistances[:-1])
        assert np.all(powers <= caps * (1 + 1e-15)), case
        assert np.any(powers >= caps * (1 - 1e-12)), case          # the limit binds somewhere


def test_bound_reads_the_scenarios_limit_and_medians_the_noise_seeds(tmp_path, capsys):
    path = resolve_scenarios(["heavy-continuous-bench-pi+ff-adaptive"])[0]
    scenario = dataclasses.replace(load_scenario(path), stop_time_s=3.0)
    short = tmp_path / "heavy-continuous-bench-pi+ff-adaptive.toml"
    short.write_text(path.read_text().replace("stop_time_s = 30.0", "stop_time_s = 3.0"))
    out = tmp_path / "bound"
    assert main(["bound", str(short), "--out", str(out)]) == 0
    assert "I <= 0.5 A, V <= 24 V" in capsys.readouterr().out
    row = json.loads((out / "bound.json").read_text())[0]
    assert (row["bound"]["current_limit_A"], row["bound"]["voltage_limit_V"]) == (0.5, 24.0)
    seeds = [scenario_metrics(run_library(with_seed(scenario, s)).data, scenario)["overall"]
             ["rmse_ohm"] for s in range(1, 6)]
    assert row["rmse_per_noise_seed_ohm"] == seeds
    assert row["rmse_ohm"] == statistics.median(seeds)
    assert len(set(seeds)) == 5                                     # each seed its own noise
    assert row["sensor"]["noise_ohm_rms"] == 0.05
