"""The C master for many runs (:class:`CMaster`): one host, FMUs loaded once, reset between runs.

What is tested is that keeping the host changes nothing a run computes: every run in a
long-lived master equals the same run in a fresh host (a C master of its own), every column
of every row to the bit, over runs with different scenarios, gains, loads, wires, sensors
(noise stream, ADC) and drive limits one after the other, after a failed step, after a host
killed by the watchdog and after a host that died between runs; that the runner and a
sweep's tasks keep one host, and that a sweep on two Dask workers gives, to the bit, the
metrics of its points run one at a time.
"""
import os
import signal
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from sma_fmu.cosim.metrics import StreamingMetrics
from sma_fmu.cosim.recording import RunRecorder
from sma_fmu.cosim.scenario import PAPER_SET, load_scenario, resolve_scenarios
from sma_fmu.studies.overrides import template
from sma_fmu.studies.runs import metrics_record
from sma_fmu.systems import c_master
from sma_fmu.systems.c_master import CMaster, CMasterError, run_c_master
from system_needs import needs
from discarding import MESSAGE, discarding, valid_path

pytestmark = needs("gcc")

PWM = "setpoints-pwm-pi+ff-adaptive"


@pytest.fixture
def started(monkeypatch):
    """The host processes the C master starts from now on (recorded, not changed)."""
    hosts = []

    class Recorded(subprocess.Popen):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            hosts.append(self)

    monkeypatch.setattr(c_master.subprocess, "Popen", Recorded)
    return hosts


def _scenario(name, overrides=None):
    if overrides:
        return template(name).scenario(overrides)
    return load_scenario(resolve_scenarios([name])[0])


def _same(a, b):
    assert a.dtype == b.dtype and a.shape == b.shape
    for name in a.dtype.names:
        assert np.array_equal(a[name], b[name], equal_nan=a[name].dtype != bool), name


def _varied():
    """Runs that differ in scenario (the components too: PI only, with a compensator, with
    a PWM driver), gains, load, wire, hysteresis mode, the bench's sensor (its noise stream
    and its sample held in the PI's state) and the driver's limit, short enough for a test."""
    short = {"scenario.stop_time_s": 3.0}
    return [_scenario(name, short) for name in PAPER_SET[:3]] + [
        _scenario(PWM, short),
        _scenario("heavy-pi", {**short, "controller.Kp_W_per_ohm": 1.7, "controller.Ki_W_per_ohm_s": 6.0}),
        _scenario("load-step-pi+ff-adaptive", {**short, "load.values_kg": 0.1}),
        _scenario("load-step-pi+ff-fixed", {**short, "wire.a_h": 70.0, "plant.hysteresis_mode": "continuous"}),
        _scenario("heavy-pi", short),   # the first scenario's components again, other values before
        _scenario("load-step-bench-pi+ff-adaptive", short),
        _scenario("load-step-bench-pi+ff-adaptive", {**short, "sensor.seed": 3, "drive.I_max_A": 0.3}),
        _scenario("heavy-continuous-bench-pi", short),
    ]


def test_runs_after_a_reset_equal_fresh_runs_to_the_bit(native_dir, started):
    scenarios = _varied()
    fresh = [run_c_master(s, native_dir).data for s in scenarios]
    assert len(started) == len(scenarios)
    del started[:]
    with CMaster(native_dir) as master:
        for order in (scenarios, scenarios[::-1]):
            for scenario in order:
                _same(master.run(scenario).data, fresh[scenarios.index(scenario)])
        assert master.hosts_started == 1 and master.startup_s > 0
    assert len(started) == 1 and started[0].returncode == 0   # stdin closed: it ended itself
    assert not np.array_equal(fresh[4]["P"], fresh[7]["P"])   # the gains changed the run
    assert not np.array_equal(fresh[5]["R"], fresh[2]["R"])   # and so did the load
    assert not np.array_equal(fresh[8]["P"], fresh[9]["P"])   # and the sensor's seed, the limit


def test_a_failed_step_ends_its_run_only(native_dir, started, tmp_path, monkeypatch):
    """A discard mid-run: the same named error and rows as in a fresh host; the host stays
    (no new process), and the runs after it, CSV written by the host included, are fresh ones."""
    discard, after = discarding(tmp_path, monkeypatch), _scenario("heavy-pi+ff-fixed")
    with pytest.raises(CMasterError) as alone:
        run_c_master(discard, native_dir)
    expected = run_c_master(after, native_dir).data
    del started[:]
    with CMaster(native_dir) as master:
        master.run(after)
        for attempt in range(2):
            with pytest.raises(CMasterError) as caught:
                master.run(discard)
            assert str(caught.value) == str(alone.value) and caught.value.status == 2
            _same(caught.value.rows, alone.value.rows)
            _same(master.run(after).data, expected)
        texts = []
        for kind in ("host", "python"):
            folder = tmp_path / kind
            folder.mkdir()
            recorder = RunRecorder(after, folder, 3, "csv")
            if kind == "python":
                recorder.csv_for_host = None   # Python formats the rows itself
            master.run(after, recorder)
            recorder.close()
            texts.append((folder / "timeseries.csv").read_bytes())
        assert texts[0] == texts[1]
        assert master.hosts_started == 1
    assert len(started) == 1


def test_a_hung_host_is_replaced_and_the_next_run_is_fresh(native_dir, started, tmp_path):
    """The watchdog kills a host stopped mid-run (SIGSTOP); the master's next run starts a
    new host and equals a fresh run. A host killed between runs is replaced as well."""
    valid_path(tmp_path, 600.0, "long")
    scenario = _scenario("load-step-pi+ff-adaptive")
    expected = run_c_master(scenario, native_dir).data
    del started[:]
    stopped = []

    def stop_once(block):
        if not stopped:
            stopped.append(os.kill(started[-1].pid, signal.SIGSTOP))

    with CMaster(native_dir, timeout_s=1.0) as master:
        with pytest.raises(CMasterError, match="no output for 1 s at t = .* the host was stopped"):
            master.run(load_scenario(tmp_path / "long.toml"), stop_once)
        assert started[0].returncode == -signal.SIGKILL
        _same(master.run(scenario).data, expected)
        started[-1].kill()   # between runs: dead before the next one starts
        started[-1].wait()
        _same(master.run(scenario).data, expected)
        assert master.hosts_started == 3
    assert len(started) == 3


def test_the_runner_keeps_one_host_for_all_its_scenarios(native_dir, started, tmp_path):
    from sma_fmu.systems.runner import run_scenarios

    paths = resolve_scenarios(["heavy-pi", "heavy-pi+ff-adaptive", PWM])
    said = []
    rows = run_scenarios(paths, tmp_path / "c", "fmu", native_dir, progress=said.append,
                         master="c", figures=False)
    assert len(started) == 1 and started[0].returncode == 0
    assert rows[0]["startup_s"] > 0 and all(row["wall_time_s"] > 0 for row in rows)
    assert not list((tmp_path / "c").rglob("*.png"))
    for name in ("heavy-pi", "heavy-pi+ff-adaptive", PWM):
        assert (tmp_path / "c" / name / "timeseries.csv").stat().st_size > 1_000_000


def test_figures_are_drawn_on_demand_and_every_other_file_is_alike(native_dir, tmp_path):
    """Without --figures (the default) or with --no-figures: every file --figures writes
    but the PNGs, byte for byte."""
    from sma_fmu.cli import main

    files = {}
    for flag in ("--figures", None, "--no-figures"):
        out = tmp_path / str(flag)
        assert main(["run", "heavy-pi", "heavy-pi+ff-fixed", "--fmus", str(native_dir), "--master",
                     "c", "--out", str(out), *([flag] if flag else [])]) == 0
        files[flag] = {p.relative_to(out): p for p in out.rglob("*") if p.is_file()}
    pictures = {name for name in files["--figures"] if name.suffix == ".png"}
    assert {name.as_posix() for name in pictures} == {
        "heavy-pi/figure.png", "heavy-pi+ff-fixed/figure.png", "comparison-heavy.png"}
    for flag in (None, "--no-figures"):
        assert set(files[flag]) == set(files["--figures"]) - pictures
        for name in ("heavy-pi/timeseries.csv", "heavy-pi+ff-fixed/timeseries.csv", "comparison.md"):
            assert files[flag][Path(name)].read_bytes() == files["--figures"][Path(name)].read_bytes()


def test_a_sweep_task_keeps_the_workers_master(native_dir, started, tmp_path, monkeypatch):
    """Two tasks in one process, a failed run among them: one host for both, each row the
    metrics of its point run one at a time in a C master of its own, to the bit."""
    from sma_fmu.studies.spec import StudyRunSpec
    from sma_fmu.studies.tasks import close_worker_masters, run_task

    close_worker_masters()
    discarding(tmp_path, monkeypatch)
    bases = [template("load-step-pi+ff-adaptive"), template(tmp_path / "discard.toml")]
    points = [(0, {"scenario.stop_time_s": 2.0, "controller.Kp_W_per_ohm": kp}) for kp in (0.2, 0.9, 0.5)]
    points.insert(2, (1, {}))
    runs = [StudyRunSpec(i, base, point) for i, (base, point) in enumerate(points)]
    rows = run_task(bases, runs[:2], native_dir) + run_task(bases, runs[2:], native_dir)
    assert len(started) == 1
    assert [row["status"] for row in rows] == ["ok", "ok", "failed", "ok"]
    assert MESSAGE in rows[2]["error"]   # the host's rows up to t = 0.5 s, then the metrics
    del started[:]
    for row, (base, point) in zip(rows, points):
        if row["status"] != "ok":
            continue
        scenario = bases[base].scenario(point)
        metrics = StreamingMetrics(scenario)
        run_c_master(scenario, native_dir, metrics.update)
        expected = metrics_record(metrics.result())
        assert {key: row[key] for key in expected} == expected
    close_worker_masters()
    assert all(host.returncode == 0 for host in started)


GRID = """
[study]
scenarios = ["load-step-pi", "load-step-pi+ff-adaptive"]
seed = 2
[overrides]
"scenario.stop_time_s" = 4.0
[axes]
kind = "grid"
[axes.values]
"controller.Kp_W_per_ohm" = { low = 0.1, high = 2.0, num = 3, log = true }
"controller.Ki_W_per_ohm_s" = [0.5, 8.0]
"""


def test_a_sweep_on_two_workers_equals_its_points_one_at_a_time(native_dir, tmp_path):
    """``sma-fmu sweep --fmus --workers 2`` (two Dask worker processes, each with its
    long-lived C master): every run's metrics are those of its point run alone in a fresh
    C master, to the bit."""
    from sma_fmu.cli import main
    from sma_fmu.studies.spec import load_spec

    spec_path = tmp_path / "grid.toml"
    spec_path.write_text(GRID, encoding="utf-8")
    out = tmp_path / "out"
    assert main(["sweep", str(spec_path), "--out", str(out), "--workers", "2", "--quiet",
                 "--fmus", str(native_dir)]) == 0
    table = pd.read_parquet(out / "results.parquet")
    spec = load_spec(spec_path)
    assert len(table) == len(spec.runs()) == 12 and (table["status"] == "ok").all()
    assert len(list((out / "runs").glob("part-*.parquet"))) > 1   # more than one task
    for run in spec.runs():
        scenario = spec.templates[run.base].scenario(run.overrides)
        metrics = StreamingMetrics(scenario)
        run_c_master(scenario, native_dir, metrics.update)
        row = table[table["run_id"] == run.run_id].iloc[0]
        for key, value in metrics_record(metrics.result()).items():
            assert row[key] == value or (value is None and pd.isna(row[key])), (run.run_id, key)


def test_the_study_api_runs_its_points_in_one_c_master(native_dir, started):
    from sma_fmu.studies.runs import run_many

    scenarios = [_scenario("heavy-pi", {"scenario.stop_time_s": 2.0, "controller.Kp_W_per_ohm": kp})
                 for kp in (0.3, 1.2)]
    runs = run_many(scenarios, path="fmu", fmu_dir=native_dir, master="c")
    assert len(started) == 1
    fmpy = run_many(scenarios, path="fmu", fmu_dir=native_dir)
    for c, f in zip(runs, fmpy):
        pd.testing.assert_frame_equal(c.timeseries, f.timeseries)
        assert c.metrics == f.metrics and c.path == "fmu"




@needs("wine64", "mingw-w64")
def test_the_win64_host_under_wine_keeps_its_session_too(native_dir, wine, started, tmp_path, monkeypatch):
    """The win64 loop host under wine: runs of different scenarios and a discard in one
    host process equal the same runs each in a win64 host of its own, to the bit."""
    discard = discarding(tmp_path, monkeypatch)
    short = {"scenario.stop_time_s": 2.0}
    scenarios = [_scenario(PWM, short), _scenario("heavy-pi", short),
                 _scenario("load-step-pi+ff-fixed", {**short, "load.values_kg": 0.1})]
    fresh = [run_c_master(s, native_dir, windows=wine).data for s in scenarios]
    with pytest.raises(CMasterError) as alone:
        run_c_master(discard, native_dir, windows=wine)
    del started[:]
    with CMaster(native_dir, windows=wine) as master:
        for scenario, expected in zip(scenarios, fresh):
            _same(master.run(scenario).data, expected)
        with pytest.raises(CMasterError) as caught:
            master.run(discard)
        assert str(caught.value) == str(alone.value) and "(win64, wine)" in str(caught.value)
        for scenario, expected in zip(scenarios[::-1], fresh[::-1]):
            _same(master.run(scenario).data, expected)
    assert len(started) == 1


def test_runs_given_ahead_equal_runs_one_at_a_time(native_dir, started, tmp_path, monkeypatch):
    """``run_many`` gives the host each run before the master reads the one before: the
    results (a discard among them) are those of :meth:`CMaster.run`; when the host hangs
    in a run (stopped, killed by the watchdog), the run given after it is given again to a
    new host and is a fresh run."""
    discard, long = discarding(tmp_path, monkeypatch), load_scenario(valid_path(tmp_path, 600.0, "long"))
    scenarios = _varied()[:4]
    fresh = [run_c_master(s, native_dir).data for s in scenarios]
    with pytest.raises(CMasterError) as alone:
        run_c_master(discard, native_dir)
    del started[:]
    kept = [[] for _ in range(5)]
    items = [(s, k.append) for s, k in zip(scenarios[:2] + [discard] + scenarios[2:], kept)]
    with CMaster(native_dir) as master:
        results = list(master.run_many(items))
        assert master.hosts_started == 1
    assert str(results[2]) == str(alone.value)
    for index, expected in zip((0, 1, 3, 4), fresh):
        _same(np.concatenate(kept[index]), expected)
        assert results[index].data is None and results[index].wall_time_s > 0
    stopped = []

    def stop_once(block):
        if not stopped:
            stopped.append(os.kill(started[-1].pid, signal.SIGSTOP))

    with CMaster(native_dir, timeout_s=1.0) as master:
        results = list(master.run_many([(scenarios[0], None), (long, stop_once), (scenarios[1], None)]))
    assert isinstance(results[1], CMasterError) and "no output for 1 s" in str(results[1])
    _same(results[0].data, fresh[0])
    _same(results[2].data, fresh[1])
    assert len(started) == 3   # one for the first batch, two here: the hung one and its successor


def test_the_pythonfmu_family_is_reset_to_a_fresh_run_too(fmus, started):
    """The default FMUs (pythonfmu slaves behind the C front): fmi2Reset gives a fresh
    slave, so runs of different scenarios in one host equal runs each in a host of its own."""
    folder = fmus["SmaActuator"].parent
    scenarios = [_scenario(name, {"scenario.stop_time_s": 2.0})
                 for name in (PWM, "heavy-pi", "load-step-pi+ff-adaptive")]
    fresh = [run_c_master(s, folder).data for s in scenarios]
    del started[:]
    with CMaster(folder) as master:
        for scenario, expected in zip(scenarios + scenarios[::-1], fresh + fresh[::-1]):
            _same(master.run(scenario).data, expected)
    assert len(started) == 1
