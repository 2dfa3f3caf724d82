"""Scenario values that pass as numbers but break a run later are refused at load, naming
the file and the key."""
import pytest

from sma_fmu.cosim.scenario import ScenarioError, load_scenario

BASE = """[scenario]
stop_time_s = 1.0
step_s = 0.001
[reference]
kind = "constant"
value_ohm = 42.0
[load]
times_s = [0.0]
values_kg = [0.05]
[controller]
kind = "pi+ff-adaptive"
"""


@pytest.mark.parametrize("extra,words", [
    ("alpha_s = 1e308\n", r"\[controller\] alpha_s = 1e\+308"),
    ("[plant]\nT_start_degC = -300\n", r"\[plant\] T_start_degC = -300.0 must be above -273.15"),
    ("[plant]\nT_start_degC = 1e300\n", r"\[plant\] T_start_degC = 1e\+300 .* validity.T_max"),
])
def test_scenario_values_that_would_break_the_run_name_the_file(tmp_path, extra, words):
    path = tmp_path / "bad.toml"
    path.write_text(BASE + extra, encoding="utf-8")
    with pytest.raises(ScenarioError, match=words) as error:
        load_scenario(path)
    assert str(error.value).startswith(str(path))


def test_the_same_scenario_with_sane_values_loads(tmp_path):
    path = tmp_path / "good.toml"
    path.write_text(BASE + "alpha_s = 1.0\n[plant]\nT_start_degC = 40.0\n", encoding="utf-8")
    assert load_scenario(path).T_start == 40.0


@pytest.mark.parametrize("frequency", ["5e-324", "1e308"])
def test_a_pwm_frequency_outside_the_driver_range_names_the_file(tmp_path, frequency):
    path = tmp_path / "pwm.toml"
    path.write_text(BASE + f'[drive]\nkind = "pwm"\nfrequency_Hz = {frequency}\npeak_W = 4.0\n',
                    encoding="utf-8")
    with pytest.raises(ScenarioError, match=r"\[drive\] frequency_Hz must be in \[1e-06, 1e\+09\] Hz"):
        load_scenario(path)
