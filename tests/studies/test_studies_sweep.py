"""sma-fmu sweep: specs, a local cluster, separate scheduler and worker processes, resume,
failures recorded, Monte Carlo from a fit report."""
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from sma_fmu.cli import main
from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.files.package_data import shipped_file
from sma_fmu.studies import StudyError, template
from sma_fmu.studies.design import monte_carlo_draws
from sma_fmu.studies.spec import StudyRunSpec, load_spec
from sma_fmu.studies.tasks import run_task
from sma_fmu.studies.results import read_parts
from sma_fmu.studies.sweep import _error_rows, _write_part, finished_runs, run_sweep

GRID = """
[study]
description = "test grid"
scenarios = ["load-step-pi+ff-adaptive", "heavy-pi"]
seed = 3

[overrides]
"scenario.stop_time_s" = 3.0

[axes]
kind = "grid"
[axes.values]
"controller.Kp_W_per_ohm" = [0.3, -1.0, 1.0]
"controller.Ki_W_per_ohm_s" = { low = 0.5, high = 4.0, num = 2, log = true }
"""


@pytest.fixture(scope="module")
def grid_spec(tmp_path_factory):
    path = tmp_path_factory.mktemp("spec") / "grid.toml"
    path.write_text(GRID, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def dask_processes(tmp_path_factory):
    """A Dask scheduler and a worker as separate processes on loopback, random free ports."""
    folder = tmp_path_factory.mktemp("dask")
    scheduler_file = folder / "scheduler.json"
    dask = str(Path(sys.executable).parent / "dask")
    env = dict(os.environ, PYTHONWARNINGS="ignore")
    processes = [subprocess.Popen(
        [dask, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
         "--scheduler-file", str(scheduler_file)], env=env, cwd=folder,
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        deadline, address = time.monotonic() + 60, None
        while address is None and time.monotonic() < deadline:
            time.sleep(0.2)
            try:      # the scheduler writes the file when it listens
                address = json.loads(scheduler_file.read_text())["address"]
            except (FileNotFoundError, json.JSONDecodeError, KeyError):
                pass
        assert address, "the dask scheduler did not start within 60 s"
        processes.append(subprocess.Popen(
            [dask, "worker", address, "--nworkers", "1", "--nthreads", "1", "--no-dashboard",
             "--no-nanny", "--host", "127.0.0.1"], env=env, cwd=folder,
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        yield address
    finally:
        for process in reversed(processes):   # ours: stopped by their handles, at once
            process.kill()
            process.wait()


@pytest.fixture(scope="module")
def local_results(grid_spec, tmp_path_factory):
    """The grid run through the command line on its default local cluster (one worker)."""
    out = tmp_path_factory.mktemp("local") / "out"
    assert main(["sweep", str(grid_spec), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    return out


def _comparable(table):
    return table.drop(columns=["path"]).sort_values("run_id").reset_index(drop=True)


def test_local_sweep_writes_table_summary_and_figures(local_results):
    table = pd.read_parquet(local_results / "results.parquet")
    assert len(table) == 12 and list(table["run_id"]) == list(range(12))
    csv = pd.read_csv(local_results / "results.csv")
    assert list(csv.columns) == list(table.columns) and len(csv) == 12
    failed = table[table["status"] == "failed"]
    assert len(failed) == 4 and set(failed["controller.Kp_W_per_ohm"]) == {-1.0}
    assert failed["error"].str.contains("Kp_W_per_ohm must be >= 0, got -1.0").all()
    ok = table[table["status"] == "ok"]
    assert (ok["path"] == "batch").all() and (ok["rmse_ohm"] > 0).all()
    assert set(ok["scenario"]) == {"load-step-pi+ff-adaptive", "heavy-pi"}
    summary = json.loads((local_results / "summary.json").read_text())
    assert summary["status"] == {"ok": 8, "failed": 4, "error": 0}
    best = summary["scenarios"]["heavy-pi"]["best"]
    heavy = ok[ok["scenario"] == "heavy-pi"]
    assert best["rmse_ohm"] == pytest.approx(heavy["rmse_ohm"].min())
    assert "| heavy-pi | 4 |" in (local_results / "summary.md").read_text()
    for name in ("heatmap-heavy-pi.png", "heatmap-load-step-pi+ff-adaptive.png"):
        assert (local_results / "figures" / name).stat().st_size > 10000


def test_separate_scheduler_and_worker_give_the_local_results(grid_spec, local_results,
                                                               dask_processes, tmp_path):
    summary = run_sweep(grid_spec, tmp_path / "remote", scheduler=dask_processes, progress=False)
    assert summary["status"]["ok"] == 8
    remote = pd.read_parquet(tmp_path / "remote" / "results.parquet")
    local = pd.read_parquet(local_results / "results.parquet")
    pd.testing.assert_frame_equal(_comparable(remote), _comparable(local))


def test_rerun_resumes_and_redoes_only_missing_runs(grid_spec, dask_processes, tmp_path):
    out = tmp_path / "out"
    run_sweep(grid_spec, out, scheduler=dask_processes, progress=False)
    parts = sorted((out / "runs").glob("part-*.parquet"))
    stamps = {p.name: p.stat().st_mtime_ns for p in parts}
    first = pd.read_parquet(out / "results.parquet")
    run_sweep(grid_spec, out, scheduler=dask_processes, progress=False)   # nothing to do
    assert {p.name: p.stat().st_mtime_ns for p in (out / "runs").glob("part-*")} == stamps
    lost = set(pd.read_parquet(parts[0])["run_id"])
    parts[0].unlink()                                                     # as if interrupted
    run_sweep(grid_spec, out, scheduler=dask_processes, progress=False)
    again = {p.name: p for p in (out / "runs").glob("part-*.parquet")}
    assert all(again[p.name].stat().st_mtime_ns == stamps[p.name] for p in parts[1:])
    redone = set().union(*(set(pd.read_parquet(p)["run_id"]) for name, p in again.items()
                           if name not in stamps))
    assert redone == lost
    pd.testing.assert_frame_equal(pd.read_parquet(out / "results.parquet"), first)
    other = grid_spec.with_name("other.toml")
    other.write_text(GRID.replace("seed = 3", "seed = 4").replace("num = 2", "num = 3"))
    with pytest.raises(StudyError, match="another study spec"):
        run_sweep(other, out, scheduler=dask_processes, progress=False)


@pytest.fixture(scope="module")
def fit_report(tmp_path_factory):
    out = tmp_path_factory.mktemp("fit") / "fit"
    assert main(["fit", "constant-load", str(shipped_file("examples", "constant_load.csv")),
                 "--out", str(out)]) == 0
    return out / "report.json"


def test_fit_report_carries_the_covariance(fit_report):
    report = json.loads(fit_report.read_text())
    names, matrix = report["covariance"]["parameters"], np.array(report["covariance"]["matrix"])
    assert names == list(report["parameters"]) and matrix.shape == (len(names), len(names))
    np.testing.assert_allclose(matrix, matrix.T, rtol=1e-12)
    np.testing.assert_allclose(np.sqrt(np.diag(matrix)),
                               [report["parameters"][n]["std_error"] for n in names], rtol=1e-12)
    assert np.all(np.linalg.eigvalsh(matrix) > 0)


def test_monte_carlo_draws_follow_the_report(fit_report):
    report = json.loads(fit_report.read_text())
    draws = monte_carlo_draws(fit_report, 4000, ["a_h", "a_c", "R_P"], seed=5)
    values = np.array([[d[n] for n in ("a_h", "a_c", "R_P")] for d in draws])
    names = report["covariance"]["parameters"]
    index = [names.index(n) for n in ("a_h", "a_c", "R_P")]
    expected = np.array(report["covariance"]["matrix"])[np.ix_(index, index)]
    mean = [report["parameters"][n]["value"] for n in ("a_h", "a_c", "R_P")]
    assert np.all(np.abs(values.mean(axis=0) - mean) < 4 * np.sqrt(np.diag(expected) / 4000))
    scale = np.sqrt(np.outer(np.diag(expected), np.diag(expected)))   # correlations within 0.1
    assert np.all(np.abs(np.cov(values.T) - expected) < 0.1 * scale)
    assert monte_carlo_draws(fit_report, 3, None, seed=5) == monte_carlo_draws(fit_report, 3, None, 5)


def test_monte_carlo_sweep_from_the_shipped_spec(fit_report, dask_processes, tmp_path):
    spec = tmp_path / "monte-carlo.toml"
    text = shipped_file("examples", "monte-carlo.toml").read_text()
    text = text.replace("samples = 1000", "samples = 5").replace(
        'report = "fit/report.json"', f'report = "{fit_report.as_posix()}"')
    spec.write_text(text + '\n[overrides]\n"scenario.stop_time_s" = 3.0\n')
    summary = run_sweep(spec, tmp_path / "mc", scheduler=dask_processes, progress=False)
    table = pd.read_parquet(tmp_path / "mc" / "results.parquet")
    assert summary["runs"] == 15 and summary["status"]["ok"] == 15
    assert table["wire.a_h"].nunique() == 5 and "model.a_h" not in table
    assert list(table["draw"][:5]) == [0, 1, 2, 3, 4]
    for name in ("load-step-pi", "load-step-pi+ff-adaptive"):
        assert (tmp_path / "mc" / "figures" / f"distribution-{name}.png").stat().st_size > 10000


@pytest.mark.parametrize("text, message", [
    ("[study]\nscenarios = []\n", "scenarios must be a non-empty list"),
    ("[study]\nscenarios = ['nope']\n", "unknown scenario 'nope'"),
    ("[study]\nscenarios = ['heavy-pi']\n[axes]\nkind = 'sobol'\n", "kind must be one of grid"),
    ("[study]\nscenarios = ['heavy-pi']\n[axes]\nkind = 'lhs'\n[axes.values]\n"
     "'controller.Kp_W_per_ohm' = {low = 1.0, high = 2.0}\n", "samples must be a whole number"),
    ("[study]\nscenarios = ['heavy-pi']\n[axes.values]\n'controller.Kp_W_per_ohm' = "
     "{low = 2.0, high = 1.0, num = 3}\n", "needs low <= high"),
    ("[study]\nscenarios = ['heavy-pi']\n[monte_carlo]\nreport = 'missing.json'\n",
     "missing.json not found; make it with: sma-fmu fit"),
    ("[study]\nscenarios = ['heavy-pi']\n[overrides]\n'controller.Ki_W_per_ohm_s' = -2\n",
     "Ki_W_per_ohm_s must be >= 0, got -2"),
    ("[study]\nscenarios = ['heavy-pi']\n[extra]\n", "unknown section \\[extra\\]"),
    ("[study]\nscenarios = ['load-step-pi+ff-adaptive', 'heavy-pi']\n[overrides]\n"
     "'controller.inverse' = 'minor-loop'\n[axes.values]\n'controller.Kp_W_per_ohm' = [0.1, 0.2]\n",
     "heavy-pi.toml: \\[controller\\] inverse = 'minor-loop' needs a feedforward controller"),
])
def test_bad_specs_are_refused_before_any_run(tmp_path, text, message):
    spec = tmp_path / "bad.toml"
    spec.write_text(text)
    with pytest.raises(StudyError, match=message):
        load_spec(spec)


def test_spec_lists_its_runs_once(grid_spec):
    spec = load_spec(grid_spec)
    assert spec.runs() is spec.runs() and len(spec.runs()) == 12
    assert [run.run_id for run in spec.runs()] == list(range(12))
    assert spec.inputs == ["controller.Kp_W_per_ohm", "controller.Ki_W_per_ohm_s"]


def test_cli_error_is_one_line_and_writes_nothing(tmp_path, capsys):
    spec = tmp_path / "bad.toml"
    spec.write_text("[study]\nscenarios = ['heavy-pi']\n[axes]\nkind = 'sobol'\n")
    assert main(["sweep", str(spec), "--out", str(tmp_path / "out")]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and error.startswith("sma-fmu: error:") and "bad.toml" in error
    assert not (tmp_path / "out").exists()


def test_a_task_runs_both_inverses_in_the_batch():
    base = template("load-step-pi+ff-adaptive")
    overrides = [{"scenario.stop_time_s": 3.0, "controller.inverse": inverse}
                 for inverse in ("major", "minor-loop")]
    rows = run_task([base], [StudyRunSpec(i, 0, o) for i, o in enumerate(overrides)])
    assert [row["path"] for row in rows] == ["batch", "batch"]
    assert [row["status"] for row in rows] == ["ok", "ok"]
    for row, changes in zip(rows, overrides):
        item = base.scenario(changes)
        expected = scenario_metrics(run_library(item).data, item)["overall"]["rmse_ohm"]
        assert row["rmse_ohm"] == pytest.approx(expected, rel=1e-12)
    assert rows[0]["rmse_ohm"] != rows[1]["rmse_ohm"]      # the minor-loop inverse differs


def test_a_final_status_beats_a_task_error(grid_spec, tmp_path):
    """Runs of a failed task are not finished; once run again, their rows replace the error."""
    spec = load_spec(grid_spec)
    runs, out = spec.runs()[:3], tmp_path / "out"
    _write_part(out, _error_rows(spec, runs, "task failed: KilledWorker: gone"))
    assert finished_runs(out) == {}
    rows = run_task(spec.templates, runs[1:])               # Kp = 0.3 (ok), -1.0 (failed)
    _write_part(out, rows)
    assert finished_runs(out) == {1: "ok", 2: "failed"}
    table = read_parts(out)
    assert list(table["run_id"]) == [0, 1, 2]
    assert list(table["status"]) == ["error", "ok", "failed"]
    assert table["error"][0] == "task failed: KilledWorker: gone"
    assert table["rmse_ohm"][1] == rows[0]["rmse_ohm"] and table["error"][2] == rows[1]["error"]


def test_a_sweep_that_cannot_reach_its_scheduler_leaves_no_folder(grid_spec, tmp_path):
    """study.json is written once the cluster is up: a failed start left it, alone, in a new
    --out folder (a failed command leaves its output folder as it was)."""
    import socket
    with socket.socket() as probe:   # a loopback port nothing listens on
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    with pytest.raises(StudyError, match="cannot connect"):
        run_sweep(grid_spec, tmp_path / "out", scheduler=f"tcp://127.0.0.1:{port}", progress=False)
    assert list(tmp_path.iterdir()) == []


def test_a_sweep_beside_another_cluster_prints_nothing_of_dask(tmp_path):
    """The scheduler's HTTP server took Dask's default port, 8787: with it in use (another
    sweep, a notebook's cluster), Dask printed a four-line 'Port 8787 is already in use'."""
    import socket
    with socket.socket() as holder:
        try:
            holder.bind(("0.0.0.0", 8787))
            holder.listen()
        except OSError:
            pass   # in use already: the case itself
        result = subprocess.run([sys.executable, "-m", "sma_fmu", "sweep",
                                 str(shipped_file("examples", "gain-grid.toml")), "--out",
                                 str(tmp_path / "out"), "--workers", "2", "--quiet"],
                                capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert result.returncode == 0 and result.stderr == "", result.stderr[-2000:]
