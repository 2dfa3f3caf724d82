"""sma-fmu tune: better gains than the scenario's, a snippet that pastes into the scenario."""
import json
import sys

import pytest

from sma_fmu.cli import main
from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.scenario import read_scenario_document, resolve_scenarios, scenario_from_document

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def test_tune_improves_and_the_snippet_reproduces_the_rmse(tmp_path, capsys):
    out = tmp_path / "tune"
    assert main(["tune", "load-step-pi", "heavy-pi+ff-adaptive",
                 "load-step-continuous-pi+ff-adaptive-minor-loop", "--stop-time", "3",
                 "--generations", "3", "--population", "4", "--out", str(out)]) == 0
    assert "written:" in capsys.readouterr().out
    records = json.loads((out / "report.json").read_text())
    assert [r["scenario"] for r in records] == ["load-step-pi", "heavy-pi+ff-adaptive",
                                                "load-step-continuous-pi+ff-adaptive-minor-loop"]
    assert set(records[1]["tuned"]) == set(records[2]["tuned"]) == {"Kp", "Ki", "alpha", "beta"}
    for record in records:
        # the scenario's own gains are in the first population, so tuning cannot lose
        assert record["rmse_ohm"]["tuned"] <= record["rmse_ohm"]["given"] + 1e-12
        assert record["rmse_ohm"]["tuned_batch"] == pytest.approx(record["rmse_ohm"]["tuned"],
                                                                   rel=1e-12)
        snippet = (out / record["scenario"] / "controller.toml").read_text()
        path = resolve_scenarios([record["scenario"]])[0]
        document = read_scenario_document(path)
        document["controller"] = tomllib.loads(snippet)["controller"]
        document["scenario"]["stop_time_s"] = 3.0
        pasted = scenario_from_document(document, path)
        rmse = scenario_metrics(run_library(pasted).data, pasted)["overall"]["rmse_ohm"]
        assert rmse == pytest.approx(record["rmse_ohm"]["tuned"], rel=1e-12)
    assert "| load-step-pi |" in (out / "report.md").read_text()


@pytest.mark.parametrize("stop, message", [("2.0005", "not a whole number of steps"),
                                           ("0", "must be > 0"),
                                           ("1e5", "at most 4000000 steps")])
def test_tune_refuses_a_bad_stop_time(tmp_path, capsys, stop, message):
    assert main(["tune", "heavy-pi", "--stop-time", stop, "--out", str(tmp_path / "t")]) == 2
    error = capsys.readouterr().err
    assert message in error and f"--stop-time {float(stop)!r}" in error
    assert not (tmp_path / "t").exists()


def test_tune_refuses_a_stop_time_before_the_analysis_window(tmp_path, capsys):
    """The file's [analysis] window is checked against the new duration, as in a file."""
    path = tmp_path / "windowed.toml"
    path.write_text(resolve_scenarios(["heavy-pi"])[0].read_text()
                    + "\n[analysis]\nmetrics_start_s = 2.0\n")
    assert main(["tune", str(path), "--stop-time", "1.5", "--out", str(tmp_path / "t")]) == 2
    error = capsys.readouterr().err
    assert "--stop-time 1.5" in error and str(path) in error
    assert "[analysis] metrics_start_s = 2.0 must be in [0, stop_time_s = 1.5)" in error
    assert not (tmp_path / "t").exists()
