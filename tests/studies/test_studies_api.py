"""The study API: overrides, the three paths, DataFrames and records."""
import numpy as np
import pandas as pd
import pytest

from sma_fmu.cosim.loop import COLUMN_NAMES, run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.studies import StudyError, metrics_record, run, run_many, scenario, template


def test_overrides_change_exactly_the_named_fields():
    base = scenario("heavy-pi+ff-fixed")
    changed = scenario("heavy-pi+ff-fixed", {
        "controller.Kp_W_per_ohm": 0.7, "controller.beta_s": 0.3, "scenario.stop_time_s": 4.0,
        "plant.hysteresis_mode": "continuous", "load.values_kg": 0.1, "wire.a_h": 71.0,
        "reference.amplitude_ohm": 3.0})
    assert (changed.controller.Kp, changed.controller.beta) == (0.7, 0.3)
    assert changed.controller.Ki == base.controller.Ki and changed.steps == 4000
    assert changed.hysteresis_mode == "continuous"
    assert changed.load.times == [0.0] and changed.load.values == [0.1]
    assert changed.reference.value(0.0) == pytest.approx(41.85 + 3.0)
    assert changed.params.a_h == 71.0 and changed.compensator_params.a_h == base.params.a_h
    both = scenario("heavy-pi", {"wire.a_h": 71.0, "model.a_h": 71.0})
    assert both.params.a_h == both.compensator_params.a_h == 71.0
    step = scenario("heavy-pi", {"reference.kind": "step", "reference.initial_ohm": 45.0,
                                 "reference.final_ohm": 40.0, "reference.time_s": 5.0})
    assert (step.reference.value(4.9), step.reference.value(5.0)) == (45.0, 40.0)


@pytest.mark.parametrize("overrides, message", [
    ({"controller.Kp_W_per_ohm": -1.0}, r"Kp_W_per_ohm must be >= 0, got -1.0 .*overrides"),
    ({"wire.R_P": 0.0}, r"R_P = 0.0 must be in \(0, 100000\] \[ohm\]"),
    ({"wire.Kp": 1.0}, r"use controller.Kp_W_per_ohm"),
    ({"wire.colour": 1.0}, r"unknown wire parameter 'colour'"),
    ({"gains.Kp": 1.0}, r"expected SECTION.KEY"),
    ({"plant.hysteresis_mode": "loose"}, r"hysteresis_mode must be .* got 'loose'"),
    ({"scenario.stop_time_s": 2.0005}, r"not a whole number of steps"),
])
def test_bad_overrides_name_the_field_and_value(overrides, message):
    with pytest.raises(StudyError, match=message):
        scenario("load-step-pi", overrides)


def test_library_batch_and_fmu_paths_agree(fmus):
    overrides = {"scenario.stop_time_s": 3.0, "controller.Kp_W_per_ohm": 0.6,
                 "wire.c_p": 440.0, "model.a_c": 53.0}
    results = {path: run("load-step-pi+ff-adaptive", overrides, path=path,
                         fmu_dir=fmus["SmaActuator"].parent) for path in ("library", "batch", "fmu")}
    library = results["library"].timeseries
    assert isinstance(library, pd.DataFrame) and tuple(library.columns) == COLUMN_NAMES
    assert len(library) == 3001
    for path, tolerance in (("batch", 1e-10), ("fmu", 1e-9)):
        frame = results[path].timeseries
        assert tuple(frame.columns) == COLUMN_NAMES
        np.testing.assert_allclose(frame.drop(columns="saturated").to_numpy(float),
                                   library.drop(columns="saturated").to_numpy(float),
                                   rtol=0, atol=tolerance, equal_nan=True, err_msg=path)
        assert frame["saturated"].equals(library["saturated"])
    item = results["library"].scenario
    assert results["library"].metrics == scenario_metrics(run_library(item).data, item)
    record = results["batch"].record()
    assert record["path"] == "batch" and record["controller"] == "pi+ff-adaptive"
    assert record["rmse_ohm"] == pytest.approx(results["library"].metrics["overall"]["rmse_ohm"],
                                               rel=1e-12)
    assert record["segment0_load_kg"] == 0.0032


def test_run_many_groups_by_duration_and_keeps_the_order():
    base = template("load-step-pi")
    items = [base.scenario({"scenario.stop_time_s": t, "controller.Ki_W_per_ohm_s": k})
             for t, k in ((3.0, 1.0), (4.0, 2.0), (3.0, 3.0))]
    results = run_many(items, path="batch")
    assert [r.scenario.controller.Ki for r in results] == [1.0, 2.0, 3.0]
    assert [len(r.timeseries) for r in results] == [3001, 4001, 3001]
    flat = metrics_record(results[1].metrics)
    assert flat["rmse_ohm"] == results[1].metrics["overall"]["rmse_ohm"]
    with pytest.raises(StudyError, match="path must be one of"):
        run_many(items, path="gpu")


def test_scenario_model_override_loads_that_parameter_file(tmp_path):
    """An override of scenario.model is not ignored: the plant and the compensator use that file."""
    from sma_fmu.files.package_data import shipped_file
    from sma_fmu.studies import scenario as study_scenario
    text = shipped_file("models", "reference_wire.toml").read_text().replace(
        "a_h = { value = 68.0", "a_h = { value = 71.0")
    (tmp_path / "wire.toml").write_text(text)
    changed = study_scenario("heavy-pi", {"scenario.model": str(tmp_path / "wire.toml")})
    assert changed.params.a_h == 71.0
    assert changed.compensator_params.a_h == 71.0
    with pytest.raises(StudyError, match="nowhere.toml: parameter file not found"):
        study_scenario("heavy-pi", {"scenario.model": str(tmp_path / "nowhere.toml")})
