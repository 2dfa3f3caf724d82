"""The tracking bound: below every controller and every power sequence, tight, and sensible."""
import json

import numpy as np
import pytest

from sma_fmu.analysis.inverse_tracker import OneStepInverse, track
from sma_fmu.analysis.switch_dp import _WindowMin, cell_lower_bound
from sma_fmu.analysis.tracking_bound import saturation_bound, tracking_bound
from sma_fmu.analysis.tracking_problem import TemperatureGrid, TrackingProblem
from sma_fmu.cli import main
from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.files.package_data import shipped_file
from sma_fmu.runtime.thermal import thermal_step

CONTROLLERS = ('kind = "pi"', 'kind = "pi+ff-fixed"', 'kind = "pi+ff-adaptive"',
               'kind = "pi+ff-adaptive"\ninverse = "minor-loop"')


def _short(tmp_path, mode, controller=CONTROLLERS[2], reference=None, name="short",
           loads="times_s = [0.0, 3.0]\nvalues_kg = [0.0032, 0.15]", stop=4.5):
    """The paper's load-step shortened to 4.5 s (loads 3.2 g, then 0.15 kg from 3 s)."""
    text = shipped_file("scenarios", "load-step-pi+ff-adaptive.toml").read_text()
    text = (text.replace("stop_time_s = 30.0", f"stop_time_s = {stop}")
            .replace("times_s = [0.0, 10.0, 20.0]\nvalues_kg = [0.0032, 0.05, 0.15]", loads)
            .replace('hysteresis_mode = "switch"', f'hysteresis_mode = "{mode}"')
            .replace('kind = "pi+ff-adaptive"', controller))
    if reference is not None:
        start, end = text.index("[reference]"), text.index("[load]")
        text = text[:start] + reference + "\n" + text[end:]
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return load_scenario(path)


def _rmse(scenario):
    return scenario_metrics(run_library(scenario).data, scenario)["overall"]["rmse_ohm"]


@pytest.fixture(scope="module")
def switch_bound(tmp_path_factory):
    scenario = _short(tmp_path_factory.mktemp("bound"), "switch")
    return scenario, tracking_bound(scenario)


@pytest.fixture(scope="module")
def capped_bound(switch_bound):
    """The same scenario with the power capped at 8 W."""
    return tracking_bound(switch_bound[0], power_cap=8.0)


def test_switch_bound_lies_below_every_controller_and_the_benchmark(tmp_path, switch_bound):
    scenario, bound = switch_bound
    assert 0.1 < bound.lower_bound_ohm <= bound.achievable.rmse_ohm
    assert bound.achievable.rmse_ohm - bound.lower_bound_ohm < 0.05  # tight: the optimum is known to 0.05 ohm
    for controller in CONTROLLERS:
        assert _rmse(_short(tmp_path, "switch", controller)) > bound.achievable.rmse_ohm


@pytest.mark.parametrize("capped", [False, True])
def test_switch_bound_lies_below_random_power_sequences(switch_bound, capped_bound, capped):
    """Any power sequence (here random ones, capped at 8 W or not) replayed through the plant."""
    scenario, bound = switch_bound
    lower = (capped_bound if capped else bound).lower_bound_ohm
    problem = TrackingProblem.from_scenario(scenario)
    rng = np.random.default_rng(7)
    for _ in range(6):
        levels = rng.uniform(0.0, 8.0 if capped else 20.0, problem.steps // 50 + 1)
        chatter = rng.random(problem.steps) < rng.uniform(0.0, 0.5)
        powers = np.where(chatter, 0.0, np.repeat(levels, 50)[:problem.steps])
        assert problem.rmse_of(problem.replay(powers)) >= lower


def test_power_cap_raises_the_switch_bound(switch_bound, capped_bound):
    _, bound = switch_bound
    assert capped_bound.lower_bound_ohm > bound.lower_bound_ohm
    assert capped_bound.lower_bound_ohm <= capped_bound.achievable.rmse_ohm
    assert capped_bound.achievable.rmse_ohm - capped_bound.lower_bound_ohm < 0.1
    assert capped_bound.achievable.peak_W <= 8.0 < bound.achievable.peak_W


def test_bound_rises_when_the_reference_leaves_the_band(tmp_path, switch_bound, params):
    _, inside = switch_bound
    shifted = _short(tmp_path, "switch", reference='[reference]\nkind = "cosine"\noffset_ohm = 44.85'
                     '\namplitude_ohm = 6.05\nfrequency_hz = 0.5\n', name="shifted")
    problem = TrackingProblem.from_scenario(shifted)
    lower = cell_lower_bound(problem, TemperatureGrid.for_problem(problem))
    assert inside.saturation_bound_ohm == 0.0
    # the distance to R_cold(f) from the spec's formulas (section 4), independently of the runtime
    residual = params.xi_F_inf * (1.0 - np.exp(-problem.sample_loads / params.f_F))
    cold = (params.R_P + residual * (params.R_F - params.R_P)
            + (1.0 - residual) * (0.5 * (params.R_M + params.R_F) - params.R_P))
    excess = np.maximum(problem.references - cold, 0.0)
    expected = np.sqrt(np.sum(problem.weights * excess ** 2) / problem.weights.sum())
    assert saturation_bound(problem) == pytest.approx(expected, rel=1e-12) and expected > 0.2
    assert lower > inside.lower_bound_ohm + 0.2
    assert lower >= saturation_bound(problem)


@pytest.mark.parametrize("mode", ["switch", "continuous"])
def test_slow_reachable_reference_bound_is_about_zero(tmp_path, mode):
    """A slow reference inside the band at a constant load (a load step forces an error in
    mode "switch": the branch moves faster than passive cooling can follow)."""
    slow = _short(tmp_path, mode, reference='[reference]\nkind = "sine"\noffset_ohm = 42.0'
                  '\namplitude_ohm = 2.0\nfrequency_hz = 0.05\n', name="slow",
                  loads="times_s = [0.0]\nvalues_kg = [0.05]", stop=3.0)
    bound = tracking_bound(slow)
    assert bound.lower_bound_ohm < 1e-3
    assert bound.achievable.rmse_ohm < 0.02 and bound.smooth is not None


def test_continuous_benchmark_replays_and_beats_every_controller(tmp_path):
    scenario = _short(tmp_path, "continuous")
    problem = TrackingProblem.from_scenario(scenario)
    powers, resistances = track(problem, tolerance=0.02)
    np.testing.assert_array_equal(problem.replay(powers), resistances)
    bound = tracking_bound(scenario)
    assert bound.lower_bound_ohm == bound.saturation_bound_ohm == 0.0
    assert bound.achievable.rmse_ohm <= problem.rmse_of(resistances)
    assert bound.achievable.reversals_per_s > 100  # the best chatters (see docs/compensator.md)
    assert bound.smooth.reversals_per_s <= 2 and bound.smooth.rmse_ohm > bound.achievable.rmse_ohm
    for controller in CONTROLLERS:  # a perfect-knowledge inverse beats them all by far
        assert _rmse(_short(tmp_path, "continuous", controller)) > 5.0 * bound.smooth.rmse_ohm


def test_grid_passive_step_lands_at_most_one_cell_down(switch_bound):
    scenario, _ = switch_bound
    problem = TrackingProblem.from_scenario(scenario)
    grid = TemperatureGrid.for_problem(problem)
    nodes, params = grid.nodes, problem.params
    passive = np.array([thermal_step(t, 0.0, params.T_room, params.K_th, problem.decay)
                        for t in nodes])
    assert np.all(passive[1:] > nodes[:-1]) and np.all(passive[1:] - nodes[:-1] < 1e-8)


def test_power_to_inverts_the_runtime_thermal_step(switch_bound):
    problem = TrackingProblem.from_scenario(switch_bound[0])
    params = problem.params
    for start, target in ((10.0, 70.0), (80.0, 79.99), (55.5, 55.5), (90.0, 20.0)):
        power = problem.power_to(start, target)
        assert thermal_step(start, power, params.T_room, params.K_th, problem.decay) == \
            pytest.approx(target, abs=1e-10)
    assert problem.power_to(90.0, 20.0) < 0.0 < problem.power_to(10.0, 70.0)


@pytest.mark.parametrize("mode,offset", [("switch", -1.0), ("switch", -0.05), ("continuous", -1.0),
                                         ("continuous", -0.05), ("continuous", 0.02)])
def test_one_step_inverse_lands_on_the_target(switch_bound, mode, offset):
    """From a state inside the transformation reached with two reversals, one step to R + offset.

    (In mode "switch" a small rise needs the cooling branch, far away: the one-step inverse
    is greedy there, which is why the switch-mode benchmark is the dynamic program.)
    """
    problem = TrackingProblem.from_scenario(switch_bound[0], mode=mode)
    inverse = OneStepInverse(problem)
    for power in [3.5] * 1500 + [0.0] * 100 + [3.0] * 100:  # heat, cool a little, heat again
        inverse.plant.step(power, 0.05, problem.step_s)
    before = inverse.plant.outputs.R
    assert 36.0 < before < 47.0 and (mode == "switch" or len(inverse.plant.reversals) > 0)
    target = before + offset
    power = inverse.power_for(target, 0.05)
    after = inverse.plant.step(power, 0.05, problem.step_s).R
    if offset < 0.0 or power > 0.0:  # heating is always feasible (no cap)
        assert power > 0.0 and after == pytest.approx(target, abs=1e-9)
    else:  # cooling faster than passive is not: 0 W comes closest
        assert abs(after - target) < abs(before - target)


def test_window_minimum_matches_brute_force():
    rng = np.random.default_rng(3)
    size = 200
    first = rng.integers(0, size, size)
    last = np.minimum(first + rng.integers(-3, 40, size), size - 1)
    values = rng.normal(size=size)
    window = _WindowMin(first, last, size)
    expected = [values[a:b + 1].min() if b >= a else np.inf for a, b in zip(first, last)]
    np.testing.assert_array_equal(window(values), expected)
    for index in range(size):
        best = window.argmin(values, index)
        assert (best is None) == (last[index] < first[index])
        if best is not None:
            assert values[best] == expected[index]


def test_bound_command_writes_json_and_markdown(tmp_path, capsys):
    scenario = _short(tmp_path, "continuous")
    out = tmp_path / "bound"
    assert main(["bound", str(scenario.path), "--out", str(out), "--power-cap", "10"]) == 0
    rows = json.loads((out / "bound.json").read_text())
    assert rows[0]["scenario"] == "short" and rows[0]["bound"]["power_cap_W"] == 10.0
    assert rows[0]["rmse_ohm"] == pytest.approx(_rmse(scenario), rel=1e-12)
    assert rows[0]["rmse_over_lower_bound"] is None  # the bound is 0 here
    assert "| short | continuous | pi+ff-adaptive |" in (out / "bound.md").read_text()
    assert "| short | continuous |" in capsys.readouterr().out


@pytest.mark.parametrize("argv,message", [
    (["bound", "no-such-scenario"], "unknown scenario 'no-such-scenario'"),
    (["bound", "paper", "--power-cap", "-1"], "argument --power-cap: expected a number > 0, got '-1'"),
])
def test_bound_command_errors_are_one_line(tmp_path, capsys, argv, message):
    try:
        status = main(argv + ["--out", str(tmp_path / "x")])
    except SystemExit as exit_:  # argparse's own errors
        status = exit_.code
    assert status == 2
    err = capsys.readouterr().err
    assert err.startswith("sma-fmu: error: ") and message in err and len(err.splitlines()) == 1
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize("value,bound,expected", [
    (1.0, 0.5, 2.0), (0.3, 0.3, 1.0), (1.0, 0.0, None),
    (1.0, 1e-14, None),   # a benchmark at rounding-error size: no ratio of 1e14
    (0.0, 0.2, 0.0)])
def test_a_ratio_to_a_bound_of_rounding_size_is_not_printed(value, bound, expected):
    from sma_fmu.analysis.bound_report import _ratio, _number

    assert _ratio(value, bound) == expected
    assert _number(_ratio(value, bound), 1) == ("n/a" if expected is None else f"{expected:.1f}")
