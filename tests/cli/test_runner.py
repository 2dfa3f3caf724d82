"""sma-fmu run: files written per scenario, comparison table, CLI errors."""
import json

import numpy as np
import pytest

from sma_fmu.cli import main
from sma_fmu.cosim.loop import COLUMNS


def test_run_paper_library_path_writes_everything(tmp_path, capsys):
    assert main(["run", "paper", "--path", "library", "--figures", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "[6/6] heavy-pi+ff-adaptive" in out and "RMSE" in out
    for name in ("load-step-pi", "heavy-pi+ff-adaptive"):
        folder = tmp_path / name
        header = (folder / "timeseries.csv").read_text().splitlines()[0]
        assert header == ("t_s,R_ref_ohm,R_ohm,T_degC,T_ref_degC,x_m,stroke_m,xi_P,xi_M,xi_F,"
                          "P_ff_W,P_fb_W,P_W,load_kg,saturated")
        table = np.genfromtxt(folder / "timeseries.csv", delimiter=",", skip_header=1)
        assert table.shape == (30001, len(COLUMNS))
        metrics = json.loads((folder / "metrics.json").read_text())
        assert metrics["overall"]["rmse_ohm"] > 0 and metrics["window"] == "t >= 2 s"
        assert (folder / "figure.png").stat().st_size > 20000
    assert (tmp_path / "comparison-load-step.png").stat().st_size > 20000
    comparison = (tmp_path / "comparison.md").read_text()
    assert comparison.count("**holds**") == 2
    assert "| 1 | pi+ff-adaptive |" in comparison and "| 3 | pi |" in comparison


def test_run_one_scenario_through_the_fmus(tmp_path, fmus, capsys):
    fmu_dir = str(fmus["SmaActuator"].parent)
    assert main(["run", "heavy-pi+ff-fixed", "--fmus", fmu_dir, "--out", str(tmp_path)]) == 0
    metrics = json.loads((tmp_path / "heavy-pi+ff-fixed" / "metrics.json").read_text())
    assert metrics["path"] == "fmu" and metrics["controller"] == "pi+ff-fixed"


@pytest.mark.parametrize("argv,message", [
    (["run", "no-such-scenario"], "unknown scenario 'no-such-scenario'"),
    (["run"], "no scenario given"),
    (["run", "heavy-pi", "--fmus", "/nonexistent"], "/nonexistent/SmaActuator.fmu not found; build"),
])
def test_run_errors(tmp_path, capsys, argv, message):
    assert main(argv + ["--out", str(tmp_path)]) == 2
    assert message in capsys.readouterr().err


def test_bad_scenario_file_stops_before_any_run(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("[scenario]\nstop_time_s = 1.0\nstep_s = 0.001\n")
    assert main(["run", "heavy-pi", str(bad), "--path", "library", "--out", str(tmp_path / "o")]) == 2
    assert "bad.toml: missing section [reference]" in capsys.readouterr().err
    assert not (tmp_path / "o" / "heavy-pi").exists()
