"""Stroke references in scenarios: reading (clear errors for bad keys and values), the library
run's stroke metrics in micrometres, and the signals FMU's refusal of a stroke table."""
import numpy as np
import pytest

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.scenario import ScenarioError, load_scenario
from sma_fmu.files.package_data import shipped_file
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.scenario_signals import signals_from_text, table_text

PROFILE = "flexinol-stroke-profile-pi+ff-adaptive"
HOLD = "flexinol-stroke-load-step-pi+ff-adaptive"


def _scenario(name):
    return load_scenario(shipped_file("scenarios", f"{name}.toml"))


def test_the_shipped_stroke_scenarios_run_on_the_flexinol_fit_with_assumed_resistances():
    for name in (PROFILE, HOLD):
        scenario = _scenario(name)
        assert scenario.reference.quantity == "stroke"
        assert scenario.parameter_set.params.terms.two_stage
        phases = shipped_file("models", "flexinol_fit.toml").read_text()
        assert phases.count("ASSUMED (the reference wire's") == 3
        assert scenario.load.values == [0.1, 0.2, 0.3]
    profile = _scenario(PROFILE)
    assert profile.reference.stroke(0.0) == pytest.approx(23e-3)
    assert profile.reference.stroke(1.0) == pytest.approx(7e-3)


def test_stroke_zero_is_the_plants_start_length():
    scenario = _scenario(HOLD)
    plant = PlantStepper(scenario.params, scenario.T_start, scenario.hysteresis_mode,
                         scenario.load.value(0.0))
    assert scenario.reference.map.start_length == plant.outputs.x


def _write(tmp_path, change):
    path = tmp_path / "stroke.toml"
    text = shipped_file("scenarios", f"{PROFILE}.toml").read_text()
    models = shipped_file("models", "flexinol_fit.toml").parent
    text = text.replace('model = "../models/', f'model = "{models}/')
    path.write_text(change(text))
    return path


@pytest.mark.parametrize("change,message", [
    (lambda s: s.replace('quantity = "stroke"', 'quantity = "position"'),
     r"\[reference\] quantity must be one of resistance, stroke, got 'position'"),
    (lambda s: s.replace("offset_mm", "offset_ohm"),
     r"\[reference\] unknown key\(s\) offset_ohm for kind 'cosine'; expected offset_mm"),
    (lambda s: s.replace("amplitude_mm = 8.0", "amplitude_mm = 1e5"),
     r"\[reference\] the stroke reference must stay within \+-10000 mm"),
    (lambda s: s.replace("offset_mm = 15.0", 'offset_mm = "15 mm"'),
     r"\[reference\] offset_mm must be a finite number, got '15 mm'"),
])
def test_a_bad_stroke_reference_names_file_key_and_value(tmp_path, change, message):
    path = _write(tmp_path, change)
    with pytest.raises(ScenarioError, match=message) as raised:
        load_scenario(path)
    assert str(path) in str(raised.value)


def test_the_signals_fmu_source_refuses_a_stroke_table():
    reference = _scenario(PROFILE).reference
    with pytest.raises(ValueError, match="reference: quantity 'stroke' is not taken here"):
        signals_from_text(table_text(reference.as_table()), table_text(
            {"times_s": [0.0], "values_kg": [0.1]}))


def test_stroke_metrics_are_the_stroke_error_in_micrometres(tmp_path):
    path = _write(tmp_path, lambda s: s.replace("stop_time_s = 30.0", "stop_time_s = 3.0")
                  .replace("times_s = [0.0, 10.0, 20.0]", "times_s = [0.0, 1.0, 2.0]"))
    scenario = load_scenario(path)
    data = run_library(scenario).data
    metrics = scenario_metrics(data, scenario)["stroke"]
    window = data["t"] >= scenario.analysis.metrics_start_s - 1e-12
    # the reference written out from the file's numbers: 15 + 8 cos(2 pi 0.5 t) mm
    reference = 1e-3 * (15.0 + 8.0 * np.cos(np.pi * data["t"][window]))
    error = data["stroke"][window] - reference
    assert metrics["rmse_um"] == pytest.approx(1e6 * np.sqrt(np.mean(error ** 2)), rel=1e-9)
    assert metrics["max_abs_um"] == pytest.approx(1e6 * np.max(np.abs(error)), rel=1e-9)
    assert metrics["samples"] == int(window.sum())
    assert len(metrics["segments_rmse_um"]) == 3


def test_the_signals_fmu_gets_the_mapped_r_ref_as_a_table_exact_at_every_step():
    from sma_fmu.fmi.loop.values import component_settings
    from sma_fmu.runtime.scenario_signals import SignalSource

    for name, most_knots in ((HOLD, 10), (PROFILE, None)):
        scenario = _scenario(name)
        settings = component_settings(scenario, "signals")
        reference, load = signals_from_text(settings["reference"], settings["load_profile"])
        knots = len(reference.settings["times_s"])
        assert knots <= (most_knots or scenario.steps + 1)
        source, h = SignalSource(reference, load), scenario.step_s
        for k in range(scenario.steps):   # the FMU's source, stepped as a host steps it
            assert source.step(k * h, h).R_ref == scenario.reference.value((k + 1) * h), k
