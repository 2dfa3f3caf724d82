"""sma-fmu tune on a stroke scenario: the stroke's RMSE [um] is what is minimised (or R's,
when chosen), named in every output, with R's numbers beside.

What the optimiser minimised (``tuned_batch``, the batch engine's number) is checked against
the stroke RMSE of the tuned gains computed here on the scalar library path from the run's
own series, not read back from tune's report.
"""
import dataclasses
import json
import statistics

import pytest

from cli_failure import fails
from sma_fmu.cli import main
from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios
from sma_fmu.files.package_data import shipped_file
from sma_fmu.studies.overrides import template
from sma_fmu.studies.robust import RobustCriterion, draw_scenarios

NAME = "flexinol-stroke-load-step-pi+ff-adaptive"
STOP = 2.0      # [s]: the start and its current limit only; enough to tell gains apart
SHORT = ["--stop-time", str(STOP), "--generations", "2", "--population", "3"]


def _short(name=NAME):
    scenario = load_scenario(resolve_scenarios([name])[0])
    return template(scenario).scenario({"scenario.stop_time_s": STOP})


def _with(scenario, gains):
    return dataclasses.replace(scenario, controller=dataclasses.replace(scenario.controller,
                                                                        **gains))


def _metrics(scenario):
    return scenario_metrics(run_library(scenario).data, scenario)


def _tune(tmp_path, *options):
    out = tmp_path / "tune"
    assert main(["tune", NAME, *SHORT, "--out", str(out), *options]) == 0
    return out, json.loads((out / "report.json").read_text())[0]


def test_a_stroke_scenario_is_tuned_on_its_stroke(tmp_path, capsys):
    out, record = _tune(tmp_path)
    assert record["criterion"] == "stroke" and record["unit"] == "um"
    scenario = _short()
    tuned, given = _metrics(_with(scenario, record["tuned"])), _metrics(scenario)
    # the optimiser's best value is the tuned gains' stroke RMSE [um], not R's [ohm]
    assert record["rmse_um"]["tuned_batch"] == pytest.approx(tuned["stroke"]["rmse_um"], rel=1e-9)
    assert tuned["stroke"]["rmse_um"] <= given["stroke"]["rmse_um"] + 1e-9
    assert record["rmse_um"]["given"] == pytest.approx(given["stroke"]["rmse_um"], rel=1e-12)
    assert record["rmse_ohm"]["tuned"] == pytest.approx(tuned["overall"]["rmse_ohm"], rel=1e-12)
    assert "tuned_batch" not in record["rmse_ohm"]
    console = capsys.readouterr().out
    assert "criterion stroke: stroke RMSE" in console and " um, RMSE " in console
    snippet = (out / NAME / "controller.toml").read_text()
    assert snippet.splitlines()[0].count("criterion stroke: stroke RMSE") == 1
    report = (out / "report.md").read_text()
    assert "## Stroke scenarios" in report and f"| {NAME} | stroke | " in report


def test_the_robust_stroke_score_is_the_draws_quantile(tmp_path):
    _, record = _tune(tmp_path, "--robust", "--draws", "2")
    robust = record["robust"]
    draws = draw_scenarios(_short(), RobustCriterion(draws=2))
    strokes = [_metrics(_with(draw, record["tuned"]))["stroke"]["rmse_um"] for draw in draws]
    assert record["rmse_um"]["tuned_batch"] == pytest.approx(statistics.median(strokes), rel=1e-9)
    assert robust["score_tuned_um"] <= robust["score_given_um"] + 1e-9
    assert len(robust["rmse_tuned_ohm"]) == 2      # R's, beside


def test_the_resistance_criterion_on_a_stroke_scenario(tmp_path, capsys):
    out, record = _tune(tmp_path, "--criterion", "resistance")
    assert record["criterion"] == "resistance" and record["unit"] == "ohm"
    tuned = _metrics(_with(_short(), record["tuned"]))
    assert record["rmse_ohm"]["tuned_batch"] == pytest.approx(tuned["overall"]["rmse_ohm"],
                                                              rel=1e-9)
    assert record["rmse_um"]["tuned"] == pytest.approx(tuned["stroke"]["rmse_um"], rel=1e-12)
    assert "criterion resistance: stroke RMSE" in capsys.readouterr().out
    assert f"| {NAME} | resistance | " in (out / "report.md").read_text()


def test_a_resistance_scenario_keeps_its_record(tmp_path):
    """The criterion of a scenario without a stroke is R's, chosen or not, and its record
    has no stroke fields (the same record as before stroke scenarios could be tuned)."""
    records = []
    for options in ([], ["--criterion", "resistance"]):
        out = tmp_path / f"tune{len(options)}"
        assert main(["tune", "heavy-pi", "--stop-time", "2.5", "--generations", "1",
                     "--population", "2", "--out", str(out), *options]) == 0
        record = json.loads((out / "report.json").read_text())[0]
        del record["optimiser"]["seconds"]
        records.append(record)
        assert "Stroke scenarios" not in (out / "report.md").read_text()
    assert records[0] == records[1]
    assert not {"criterion", "unit", "rmse_um"} & set(records[0])


def test_the_stroke_criterion_on_a_resistance_scenario_is_refused(tmp_path, capsys):
    """(A criterion that is neither: tests/cli/test_cli_errors.py.)"""
    fails(capsys, ["tune", "heavy-pi", "--criterion", "stroke", "--out", str(tmp_path / "t")],
          "--criterion stroke", "heavy-pi", "not a stroke")
    assert not (tmp_path / "t").exists()


def _paper_gains(tmp_path, name):
    """The shipped stroke scenario ``name`` at the paper's gains (far from the best: tuning
    moves every gain), as a file."""
    text = resolve_scenarios([name])[0].read_text(encoding="utf-8")
    for old, new in (('"../models/flexinol_fit.toml"', json.dumps(str(shipped_file(
                          "models", "flexinol_fit.toml")))),
                     ("Kp_W_per_ohm = 4.65", "Kp_W_per_ohm = 0.3"),
                     ("Ki_W_per_ohm_s = 0.0", "Ki_W_per_ohm_s = 1.0"),
                     ("alpha_s = 2.06", "alpha_s = 1.0"), ("beta_s = 0.45", "beta_s = 0.2")):
        assert old in text
        text = text.replace(old, new)
    path = tmp_path / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_joint_tuning_gives_one_gain_set_for_both_stroke_scenarios(tmp_path, capsys):
    paths = [_paper_gains(tmp_path, name)
             for name in (NAME, "flexinol-stroke-profile-pi+ff-adaptive")]
    out = tmp_path / "tune"
    assert main(["tune", *map(str, paths), "--joint", *SHORT, "--out", str(out)]) == 0
    records = json.loads((out / "report.json").read_text())
    assert records[0]["tuned"] == records[1]["tuned"] != records[0]["given"]
    ratios = []
    for path, record in zip(paths, records):
        scenario = template(load_scenario(path)).scenario({"scenario.stop_time_s": STOP})
        tuned, given = _metrics(_with(scenario, record["tuned"])), _metrics(scenario)
        assert record["rmse_um"]["tuned_batch"] == pytest.approx(tuned["stroke"]["rmse_um"],
                                                                 rel=1e-9)
        ratios.append(tuned["stroke"]["rmse_um"] / given["stroke"]["rmse_um"])
        assert record["joint"]["ratio"] == pytest.approx(ratios[-1], rel=1e-9)
    # the score minimised: the worst ratio, below the given gains' 1
    assert records[0]["joint"]["worst_ratio"] == pytest.approx(max(ratios), rel=1e-9)
    assert max(ratios) < 1.0
    assert "tuned jointly with" in (out / records[0]["scenario"] / "controller.toml").read_text()
    assert "jointly tuned: score" in capsys.readouterr().out


def test_joint_tuning_refuses_other_gain_sets(tmp_path, capsys):
    fails(capsys, ["tune", "heavy-pi", "heavy-pi+ff-adaptive", "--joint", "--out",
                   str(tmp_path / "t")], "--joint", "heavy-pi+ff-adaptive", "not one gain set")
    assert not (tmp_path / "t").exists()
