"""The C master (``sma-fmu run --master c``): the fmpy master's run, to the bit, stepped in C.

The same native FMUs run through the fmpy master (plant, compensator and driver FMUs; PI
and signals in Python) and through the C master (all five FMUs in loop_host.c): every
column of every row and every metric is equal (0.0 apart, NaN where NaN), for the paper's
six scenarios and both PWM ones. Then the recorder's files through the runner, and the
named errors: a missing FMU, an FMU whose variables do not match, a discard mid-run.
"""
import json
import shutil

import numpy as np
import pandas as pd
import pytest

from cli_failure import fails
from sma_fmu.cosim.master import MissingFmuError, run_fmus
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.recording import read_timeseries
from sma_fmu.cosim.scenario import PAPER_SET, load_scenario, resolve_scenarios
from sma_fmu.systems.c_master import CMasterError, run_c_master
from sma_fmu.systems.runner import run_scenarios
from system_needs import needs

pytestmark = needs("gcc")
PWM = ("setpoints-pwm-pi+ff-adaptive", "setpoints-pwm-continuous-pi+ff-adaptive")

# a PI so strong that the plant discards the step where the reference drops (t = 0.5 s)
DISCARD = """
[scenario]
stop_time_s = {stop}
step_s = 0.001
[reference]
kind = "step"
initial_ohm = 60.0
final_ohm = 1.0
time_s = 0.5
[load]
times_s = [0.0]
values_kg = [0.25]
[controller]
kind = "pi"
Kp_W_per_ohm = 1e306
"""


def _scenario(name):
    return load_scenario(resolve_scenarios([name])[0])


@pytest.fixture(scope="module")
def native_dir(native_fmus):
    return native_fmus["SmaActuator"].parent


def _same(a, b):
    assert a.dtype == b.dtype and a.shape == b.shape
    for name in a.dtype.names:
        x, y = a[name], b[name]
        assert np.array_equal(x, y, equal_nan=x.dtype != bool), name


@pytest.mark.parametrize("name", PAPER_SET + PWM)
def test_the_c_master_is_the_fmpy_master_to_the_bit(native_dir, name):
    scenario = _scenario(name)
    fmpy, c = run_fmus(scenario, native_dir), run_c_master(scenario, native_dir)
    assert c.path == fmpy.path == "fmu" and len(c.data) == scenario.steps + 1
    _same(c.data, fmpy.data)
    assert scenario_metrics(c.data, scenario) == scenario_metrics(fmpy.data, scenario)
    assert np.ptp(c.data["R"]) > 1.0 and np.ptp(c.data["P"][:-1]) > 0.1  # the loop moved


def test_the_c_master_runs_the_pythonfmu_family_too(fmus):
    """The default FMUs (pythonfmu, their C front loading libpython in the host): the same
    rows as the fmpy master over them (no faster: the slaves are Python)."""
    scenario = _scenario(PWM[0])
    folder = fmus["SmaActuator"].parent
    _same(run_c_master(scenario, folder).data, run_fmus(scenario, folder).data)


def test_the_runner_records_the_same_files_and_metrics(native_dir, tmp_path):
    paths = resolve_scenarios(["heavy-pi+ff-adaptive", PWM[0]])
    for master in ("fmpy", "c"):
        run_scenarios(paths, tmp_path / master, "fmu", native_dir, progress=lambda _: None,
                      output_interval_s=0.003, fmt="parquet", master=master)
    for path in paths:
        name = path.stem
        a = read_timeseries(tmp_path / "fmpy" / name / "timeseries.parquet")
        b = read_timeseries(tmp_path / "c" / name / "timeseries.parquet")
        assert len(a) == 10_001 and a.equals(b)
        metrics = [json.loads((tmp_path / m / name / "metrics.json").read_text()) for m in ("fmpy", "c")]
        assert [m.pop("master") for m in metrics] == ["fmpy", "c"]
        for m in metrics:
            m.pop("wall_time_s")
        assert metrics[0] == metrics[1]


def test_a_missing_fmu_is_named(native_dir, tmp_path):
    for name in ("SmaActuator", "SmaPiController", "SmaScenarioSignals"):
        shutil.copy(native_dir / f"{name}.fmu", tmp_path)
    with pytest.raises(MissingFmuError, match=r"SmaFeedforward\.fmu not found"):
        run_c_master(_scenario("heavy-pi+ff-fixed"), tmp_path)


def test_an_fmu_whose_variables_do_not_match_is_named(native_dir, tmp_path):
    for path in native_dir.glob("*.fmu"):
        shutil.copy(path, tmp_path)
    shutil.copy(native_dir / "SmaPwmDriver.fmu", tmp_path / "SmaPiController.fmu")
    with pytest.raises(ValueError, match=r"SmaPiController\.fmu: the model's variables do not "
                                         r"match the loop: pi needs input 'R_ref'"):
        run_c_master(_scenario("heavy-pi"), tmp_path)


def test_a_discard_mid_run_stops_there_keeping_the_rows(native_dir, tmp_path):
    """The plant discards the step at t = 0.5 s: the error names it, the FMU's message and
    the time; the sink got the rows up to it, equal to those of a run that ends there."""
    (tmp_path / "discard.toml").write_text(DISCARD.format(stop=1.0))
    (tmp_path / "short.toml").write_text(DISCARD.format(stop=0.5))
    got = []
    with pytest.raises(CMasterError) as caught:
        run_c_master(load_scenario(tmp_path / "discard.toml"), native_dir, sink=got.append)
    error = caught.value
    assert error.status == 2 and error.time_s == 0.5
    assert "plant: fmi2DoStep failed (fmi2Discard) at t = 0.5 s" in str(error)
    assert "floating-point range" in str(error) and "501 rows kept" in str(error)
    kept = np.concatenate(got)
    _same(kept, run_c_master(load_scenario(tmp_path / "short.toml"), native_dir).data)
    with pytest.raises(CMasterError) as again:   # without a sink: the rows are in the error
        run_c_master(load_scenario(tmp_path / "discard.toml"), native_dir)
    _same(again.value.rows, kept)


def test_the_cli_names_the_failure_and_leaves_the_folder(native_dir, tmp_path, capsys):
    (tmp_path / "discard.toml").write_text(DISCARD.format(stop=1.0))
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("kept")
    fails(capsys, ["run", str(tmp_path / "discard.toml"), "--fmus", str(native_dir),
                   "--master", "c", "--out", str(out)], "plant: fmi2DoStep failed", "t = 0.5 s")
    fails(capsys, ["run", "heavy-pi", "--path", "library", "--master", "c", "--out", str(out)],
          "--master c", "--path library")
    assert [p.name for p in out.iterdir()] == ["keep.txt"]



def test_no_compiler_for_the_host_is_a_named_error(native_dir, tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("CC", "no-such-cc")
    with pytest.raises(CMasterError, match=r"C master: C compiler 'no-such-cc' could not run"):
        run_c_master(_scenario("heavy-pi"), native_dir, cache=tmp_path)
    fails(capsys, ["run", "heavy-pi", "--fmus", str(native_dir), "--master", "c", "--out",
                   str(tmp_path / "out")], "C master", "no-such-cc")
    assert not (tmp_path / "out").exists()

GRID = """
[study]
scenarios = ["load-step-pi+ff-adaptive", "heavy-pi"]
seed = 3
[overrides]
"scenario.stop_time_s" = 2.0
[axes]
kind = "grid"
[axes.values]
"controller.Kp_W_per_ohm" = [0.3, -1.0]
"""


def test_a_sweep_task_over_native_fmus_runs_the_c_master(native_dir):
    """Each run's metrics are those of the fmpy master over the same FMUs, to the bit."""
    from sma_fmu.studies.overrides import template
    from sma_fmu.studies.runs import metrics_record
    from sma_fmu.studies.spec import StudyRunSpec
    from sma_fmu.studies.tasks import run_task

    base = template("load-step-pi+ff-adaptive")
    overrides = [{"scenario.stop_time_s": 2.0, "controller.Kp_W_per_ohm": kp} for kp in (0.3, 1.0)]
    rows = run_task([base], [StudyRunSpec(i, 0, o) for i, o in enumerate(overrides)], native_dir)
    assert [(row["path"], row["status"]) for row in rows] == [("fmu", "ok")] * 2
    for row, changes in zip(rows, overrides):
        item = base.scenario(changes)
        expected = metrics_record(scenario_metrics(run_fmus(item, native_dir).data, item))
        assert {key: row[key] for key in expected} == expected
    assert rows[0]["rmse_ohm"] != rows[1]["rmse_ohm"]


def test_sweep_over_native_fmus_and_its_folder(native_dir, tmp_path, capsys):
    from sma_fmu.cli import main

    spec = tmp_path / "grid.toml"
    spec.write_text(GRID, encoding="utf-8")
    out = tmp_path / "out"
    argv = ["sweep", str(spec), "--out", str(out), "--workers", "1", "--quiet"]
    assert main([*argv, "--fmus", str(native_dir)]) == 0
    table = pd.read_parquet(out / "results.parquet")
    assert sorted(table["path"].dropna().unique()) == ["fmu"]
    assert sorted(table["status"]) == ["failed", "failed", "ok", "ok"]   # Kp = -1 is refused
    capsys.readouterr()
    fails(capsys, argv, "holds runs of the fmu path, not batch")     # no mixing of paths
    shutil.copytree(native_dir, tmp_path / "partial")
    (tmp_path / "partial" / "SmaFeedforward.fmu").unlink()
    fails(capsys, ["sweep", str(spec), "--out", str(tmp_path / "other"), "--fmus",
                   str(tmp_path / "partial")], "SmaFeedforward.fmu not found")
    assert not (tmp_path / "other").exists()


def test_the_bench_section_compares_each_scenario_with_the_library(native_dir, tmp_path):
    """One alternating run of one scenario: both walls, their ratio and the target's verdict
    (the numbers themselves are the bench's to print, not asserted here)."""
    from sma_fmu.bench.c_master import TARGET, c_master_lines, c_master_times

    times = c_master_times(native_dir, 1, tmp_path, scenarios=("heavy-pi",), formats=("parquet",))
    row = times["heavy-pi (parquet)"]
    assert row["runs"] == 1 and row["library_s"] > 0 and row["c_s"] > 0
    assert row["ratio"] == pytest.approx(row["c_s"] / row["library_s"], rel=0.01)
    lines = c_master_lines(times)
    assert "heavy-pi (parquet)" in lines[-1] and f"target <= {TARGET:g}" in lines[-1]
    assert len(list(tmp_path.glob("heavy-pi-parquet-*/timeseries.parquet"))) == 2
