"""Scenario files: the shipped set, signals, and malformed files rejected naming file and key."""

import pytest

from sma_fmu.files.package_data import shipped_file
from sma_fmu.cosim.scenario import (CONTROLLERS, PAPER_SET, ScenarioError, load_scenario,
                              resolve_scenarios, scenario_names)
from sma_fmu.runtime.signals import load_from_table, reference_from_table

EXPECTED = {f"{profile}{mode}-{controller}" for profile in ("load-step", "heavy")
            for mode in ("", "-continuous") for controller in CONTROLLERS}


def test_shipped_scenarios_cover_both_profiles_controllers_and_modes():
    assert EXPECTED <= set(scenario_names())
    for name in EXPECTED:
        scenario = load_scenario(shipped_file("scenarios", f"{name}.toml"))
        assert scenario.steps == 30000 and scenario.step_s == 1e-3
        assert scenario.hysteresis_mode == ("continuous" if "continuous" in name else "switch")
        assert name.endswith("-" + scenario.controller.kind)
        assert scenario.reference.value(0.0) == pytest.approx(47.9)
        assert scenario.reference.value(1.0) == pytest.approx(35.8)


def test_paper_profiles_match_spec():
    step = load_scenario(shipped_file("scenarios", "load-step-pi.toml"))
    h = step.step_s
    assert [step.load.value(k * h) for k in (0, 9999, 10000, 19999, 20000, 30000)] == \
        [3.2e-3, 3.2e-3, 0.05, 0.05, 0.15, 0.15]
    assert load_scenario(shipped_file("scenarios", "heavy-pi.toml")).load.segments(30.0) == [(0.0, 30.0, 0.25)]
    assert set(PAPER_SET) == {n for n in EXPECTED if "continuous" not in n}


def test_controller_gains_default_to_the_parameter_file(params):
    scenario = load_scenario(shipped_file("scenarios", "heavy-pi+ff-fixed.toml"))
    c = scenario.controller
    assert (c.Kp, c.Ki, c.alpha, c.beta, c.model_load) == \
        (params.Kp, params.Ki, params.tau_th, params.beta, params.model_load)
    assert c.feedforward and not c.adapt_to_load
    assert scenario.T_start == params.T_room


@pytest.mark.parametrize("table,t,expected", [
    ({"kind": "constant", "value_ohm": 40.0}, 3.0, 40.0),
    ({"kind": "step", "initial_ohm": 45.0, "final_ohm": 38.0, "time_s": 2.0}, 1.999, 45.0),
    ({"kind": "step", "initial_ohm": 45.0, "final_ohm": 38.0, "time_s": 2.0}, 2.0, 38.0),
    ({"kind": "ramp", "start_ohm": 46.0, "end_ohm": 36.0, "start_time_s": 1.0, "end_time_s": 6.0}, 3.5, 41.0),
    ({"kind": "ramp", "start_ohm": 46.0, "end_ohm": 36.0, "start_time_s": 1.0, "end_time_s": 6.0}, 9.0, 36.0),
    ({"kind": "sine", "offset_ohm": 42.0, "amplitude_ohm": 4.0, "frequency_hz": 0.25}, 1.0, 46.0),
    ({"kind": "cosine", "offset_ohm": 42.0, "amplitude_ohm": 4.0, "frequency_hz": 0.25,
      "phase_deg": 90.0}, 0.0, 42.0),
    ({"kind": "table", "times_s": [0.0, 2.0, 4.0], "values_ohm": [40.0, 44.0, 36.0]}, 3.0, 40.0),
    ({"kind": "table", "times_s": [0.0, 2.0, 4.0], "values_ohm": [40.0, 44.0, 36.0]}, 9.0, 36.0),
])
def test_reference_kinds(table, t, expected):
    assert reference_from_table(table).value(t) == pytest.approx(expected, abs=1e-12)


def test_load_profile_is_piecewise_constant():
    profile = load_from_table({"times_s": [0.0, 1.5], "values_kg": [0.01, 0.2]})
    assert [profile.value(t) for t in (0.0, 1.4999, 1.5, 7.0)] == [0.01, 0.01, 0.2, 0.2]
    assert profile.segments(3.0) == [(0.0, 1.5, 0.01), (1.5, 3.0, 0.2)]


def _write(tmp_path, text):
    path = tmp_path / "custom.toml"
    base = (shipped_file("scenarios", "load-step-pi+ff-adaptive.toml")).read_text()
    path.write_text(text(base) if callable(text) else text)
    return path


@pytest.mark.parametrize("change,message", [
    (lambda s: s.replace('kind = "cosine"', 'kind = "square"'),
     r"\[reference\] kind must be one of constant, step, ramp, sine, cosine, table, got 'square'"),
    (lambda s: s.replace("offset_ohm = 41.85", "offset_ohm = 4.0"),
     r"\[reference\] the reference must stay > 0 ohm, but reaches -2.05 ohm"),
    (lambda s: s.replace("frequency_hz = 0.5", "frequency = 0.5"),
     r"\[reference\] unknown key\(s\) frequency for kind 'cosine'"),
    (lambda s: s.replace("values_kg = [0.0032, 0.05, 0.15]", "values_kg = [0.0032, -0.05, 0.15]"),
     r"\[load\] values_kg must be >= 0, got -0.05"),
    (lambda s: s.replace("times_s = [0.0, 10.0, 20.0]", "times_s = [0.0, 20.0, 10.0]"),
     r"\[load\] times_s must be strictly increasing"),
    (lambda s: s.replace("times_s = [0.0, 10.0, 20.0]", "times_s = [1.0, 10.0, 20.0]"),
     r"\[load\] times_s must start at 0, got 1.0"),
    (lambda s: s.replace('kind = "pi+ff-adaptive"', 'kind = "pid"'),
     r"\[controller\] kind must be one of pi, pi\+ff-fixed, pi\+ff-adaptive, got 'pid'"),
    (lambda s: s.replace('[controller]\n', '[controller]\nbeta_s = 0.0\n'),
     r"\[controller\] beta_s must be > 0, got 0.0"),
    (lambda s: s.replace('[controller]\n', '[controller]\nKp = 0.5\n'),
     r"\[controller\] unknown key\(s\) Kp"),
    (lambda s: s.replace('hysteresis_mode = "switch"', 'hysteresis_mode = "smooth"'),
     r"\[plant\] hysteresis_mode must be 'switch' or 'continuous', got 'smooth'"),
    (lambda s: s.replace("stop_time_s = 30.0", "stop_time_s = 30.0005"),
     r"\[scenario\] stop_time_s = 30.0005 is not a whole number of steps"),
    (lambda s: s.replace("step_s = 0.001", 'step_s = "1 ms"'),
     r"\[scenario\] step_s must be a finite number, got '1 ms'"),
    (lambda s: s.replace("[scenario]\n", '[scenario]\nmodel = "nowhere.toml"\n'),
     r"\[scenario\] model = 'nowhere.toml': .*nowhere.toml: parameter file not found"),
    (lambda s: s.replace("[load]", "[loads]"), r"unknown section \[loads\]"),
    (lambda s: s.replace("[controller]", "[control]"), r"unknown section \[control\]"),
    (lambda s: s + "\n[plant\n", r"not valid TOML"),
])
def test_malformed_scenario_names_file_key_and_problem(tmp_path, change, message):
    path = _write(tmp_path, change)
    with pytest.raises(ScenarioError, match=message) as raised:
        load_scenario(path)
    assert str(path) in str(raised.value)


def test_missing_section_is_named(tmp_path):
    text = (shipped_file("scenarios", "heavy-pi.toml")).read_text()
    path = _write(tmp_path, text[:text.index("[controller]")])
    with pytest.raises(ScenarioError, match=r"missing section \[controller\]"):
        load_scenario(path)


def test_unknown_scenario_name_suggests_the_closest_ones():
    with pytest.raises(ScenarioError, match=r"unknown scenario 'load-stpe-pi': no such file, .*"
                                            r"did you mean 'load-step-pi'(, '[^']+')*( or '[^']+')?\? "
                                            r"\(sma-fmu examples lists the 18 shipped scenarios"):
        resolve_scenarios(["load-stpe-pi"])
    with pytest.raises(ScenarioError, match=r"did you mean 'paper'\?"):
        resolve_scenarios(["papr"])
    with pytest.raises(ScenarioError) as refused:
        resolve_scenarios(["xyz"])
    assert "did you mean" not in str(refused.value) and "heavy-pi" not in str(refused.value)


def test_resolve_paper_and_all():
    assert [p.stem for p in resolve_scenarios(["paper"])] == list(PAPER_SET)
    assert len(resolve_scenarios([], everything=True)) == len(scenario_names()) >= 12
