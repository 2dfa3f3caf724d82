"""The receding-horizon benchmark with preview: achievable (its powers replay through a fresh
plant to the same R), within the driver's limit at the plant's R, no worse than the greedy
one-step inverse it builds on, and never below the rigorous switch-mode lower bound (the
cell dynamic program, an independent computation)."""
import dataclasses
import json

import numpy as np
import pytest

from sma_fmu.analysis.inverse_tracker import track
from sma_fmu.analysis.power_limit import PowerLimit
from sma_fmu.analysis.preview_search import HORIZONS, PreviewSearch
from sma_fmu.analysis.switch_dp import cell_lower_bound
from sma_fmu.analysis.tracking_bound import TOLERANCES
from sma_fmu.analysis.tracking_problem import TemperatureGrid, TrackingProblem
from sma_fmu.cli import main
from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios

CONTINUOUS = "load-step-continuous-bench-pi+ff-adaptive-reachable"   # 0.5 A, 24 V driver


def _short(name, stop=4.0):
    scenario = load_scenario(resolve_scenarios([name])[0])
    return dataclasses.replace(scenario, stop_time_s=stop)


@pytest.fixture(scope="module")
def continuous_search():
    scenario = _short(CONTINUOUS)
    problem = TrackingProblem.from_scenario(scenario)
    limit = PowerLimit.of(None, scenario)
    return problem, limit, PreviewSearch(problem, limit, horizon=200).run()   # 0.2 s: quicker


def test_the_search_replays_through_a_fresh_plant(continuous_search):
    problem, _, (powers, resistances, _) = continuous_search
    assert problem.mode == "continuous"
    np.testing.assert_array_equal(problem.replay(powers), resistances)


def test_the_search_respects_the_driver_at_the_plants_resistance(continuous_search):
    _, limit, (powers, resistances, _) = continuous_search
    caps = np.minimum(limit.current_A ** 2 * resistances[:-1], limit.voltage_V ** 2 / resistances[:-1])
    assert np.all(powers >= 0.0) and np.all(powers <= caps * (1 + 1e-15))
    assert powers.max() > 0.9 * caps.min()   # the limit is reached, so the check means something


def test_the_search_beats_the_one_step_inverse(continuous_search):
    problem, limit, (_, resistances, wins) = continuous_search
    greedy = min(problem.rmse_of(track(problem, tolerance, limit)[1]) for tolerance in TOLERANCES)
    assert problem.rmse_of(resistances) < 0.9 * greedy
    assert set(wins) - {"one-step inverse"}   # it chose something else at times


def test_the_search_never_goes_below_the_switch_bound():
    scenario = _short("heavy-bench-pi+ff-adaptive-reachable", stop=3.0)
    problem = TrackingProblem.from_scenario(scenario)
    limit = PowerLimit.of(None, scenario)
    powers, resistances, _ = PreviewSearch(problem, limit, horizon=200).run()
    lower = cell_lower_bound(problem, TemperatureGrid.for_problem(problem), limit)
    assert problem.mode == "switch" and lower > 0.1
    assert problem.rmse_of(problem.replay(powers)) == problem.rmse_of(resistances) >= lower


def test_bound_command_adds_the_preview_benchmark(tmp_path):
    path = tmp_path / "short.toml"
    path.write_text(resolve_scenarios([CONTINUOUS])[0].read_text()
                    .replace("stop_time_s = 30.0", "stop_time_s = 2.5"))
    assert main(["bound", str(path), "--preview", "--out", str(tmp_path / "out")]) == 0
    benchmarks = json.loads((tmp_path / "out" / "bound.json").read_text())[0]["bound"]["benchmarks"]
    previews = [b for b in benchmarks if b["method"].startswith("receding-horizon search")]
    others = [b for b in benchmarks if b not in previews]
    assert len(previews) == len(HORIZONS) and len(others) == len(TOLERANCES)
    assert min(b["rmse_ohm"] for b in previews) < min(b["rmse_ohm"] for b in others)
