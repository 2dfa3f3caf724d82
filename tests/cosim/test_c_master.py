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
from sma_fmu.cosim.master import run_fmus
from sma_fmu.fmi.loop.system import MissingFmuError
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.recording import RunRecorder, interval_steps, read_timeseries
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


class _PythonCsv(RunRecorder):
    """A recorder that keeps the CSV to itself: Python formats every row."""
    csv_for_host = None


@pytest.mark.parametrize("name", PAPER_SET + PWM)
def test_the_csv_the_c_master_writes_is_the_recorders_byte_for_byte(native_dir, name, tmp_path):
    """The host writes the CSV's rows itself ("csv" line); the file is the one the Python
    recorder writes from the same rows, every step and every 7th (--output-interval), and
    the metrics, figure rows and row counts are unchanged."""
    scenario = _scenario(name)
    for every in (1, interval_steps(0.007, scenario.step_s)):
        made = {}
        for kind, recorder_class in (("c", RunRecorder), ("python", _PythonCsv)):
            folder = tmp_path / f"{kind}-{every}"
            folder.mkdir()
            recorder = recorder_class(scenario, folder, every, "csv")
            run_c_master(scenario, native_dir, recorder)
            metrics, figure = recorder.close()
            made[kind] = ((folder / "timeseries.csv").read_bytes(), metrics, figure, recorder.writer.rows)
        (c_text, c_metrics, c_figure, c_rows), (p_text, p_metrics, p_figure, p_rows) = made["c"], made["python"]
        assert c_text == p_text and c_text.count(b"\n") == c_rows + 1
        assert json.dumps(c_metrics) == json.dumps(p_metrics) and c_rows == p_rows
        _same(c_figure, p_figure)
    assert c_rows == len(range(0, scenario.steps + 1, every)) + (scenario.steps % every != 0)


def test_a_discard_mid_run_leaves_the_same_csv_rows(native_dir, tmp_path):
    """The failed step's rows: the C-written CSV holds those the Python recorder writes."""
    (tmp_path / "discard.toml").write_text(DISCARD.format(stop=1.0))
    scenario = load_scenario(tmp_path / "discard.toml")
    texts = []
    for kind, recorder_class in (("c", RunRecorder), ("python", _PythonCsv)):
        folder = tmp_path / kind
        folder.mkdir()
        recorder = recorder_class(scenario, folder, 3, "csv")
        with pytest.raises(CMasterError, match="501 rows kept"):
            run_c_master(scenario, native_dir, recorder)
        recorder.close()
        texts.append((folder / "timeseries.csv").read_bytes())
    assert texts[0] == texts[1] and texts[0].count(b"\n") == 1 + len(range(0, 501, 3))


def _g10(values, windows=None):
    """The loop host's "%.10g" of each of ``values`` (its "g10" test line)."""
    import subprocess
    import struct

    from sma_fmu.fmi.hosts import compile_host
    from sma_fmu.systems.loop_host import wine_executable

    executable = compile_host("loop_host", windows=windows is not None)
    line = "g10 " + " ".join(struct.pack(">d", v).hex() for v in values) + "\n"
    command = [str(executable)] if windows is None else [wine_executable(), str(executable)]
    done = subprocess.run(command, input=line.encode(), capture_output=True, check=True,
                          env=windows, timeout=600)
    return done.stdout.decode().split()


def g10_cases(count=40_000, seed=41):
    """Edge cases of "%.10g" and random doubles: any bit pattern, any decade, near-ties."""
    import random
    import struct

    pick = random.Random(seed)
    values = [0.0, -0.0, 1e-5, -1e-5, 1e-4, 9.99999999949999e-5, 1e-10, 1e10, 9999999999.5,
              9999999999.4, 99999.999995, 1234567890.5, 1234567891.5, 123456789012.0, 1e20,
              1e30, 1e-30, 1e-31, 5e-324, 2.2250738585072014e-308, 1.7976931348623157e308,
              float("nan"), -float("nan"), float("inf"), -float("inf"), 0.1 + 0.2, 1 / 3, 30.0]
    for _ in range(count):
        r = pick.random()
        if r < 0.3:
            values.append(struct.unpack("<d", struct.pack("<Q", pick.getrandbits(64)))[0])
        elif r < 0.6:
            values.append(pick.uniform(-1, 1) * 10.0 ** pick.randint(-35, 35))
        elif r < 0.8:   # 11 significant digits ending in 5: at or next to a tie
            digits = pick.randint(10 ** 10, 10 ** 11 - 1) // 10 * 10 + 5
            values.append(pick.choice((-1, 1)) * digits * 10.0 ** pick.randint(-25, 15))
        else:
            values.append(round(pick.uniform(-100, 100), pick.randint(0, 12)))
    return values


def test_the_hosts_g10_is_pythons_percent_10g():
    values = g10_cases()
    got = _g10(values)
    assert len(got) == len(values)
    wrong = [(v, text, "%.10g" % v) for v, text in zip(values, got) if text != "%.10g" % v]
    assert wrong == []


def _stopping_popen(monkeypatch, when):
    """Popen for the C master's host that records each host and, ``when`` "spawned", stops
    it at once with SIGSTOP (a host that hangs before its first row); the hosts started."""
    import os
    import signal
    import subprocess

    from sma_fmu.systems import c_master

    hosts = []

    class Stopping(subprocess.Popen):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            hosts.append(self)
            if when == "spawned":
                os.kill(self.pid, signal.SIGSTOP)

    monkeypatch.setattr(c_master.subprocess, "Popen", Stopping)
    return hosts


def test_a_host_that_falls_silent_mid_run_is_killed_and_named(native_dir, tmp_path, monkeypatch):
    """The host is stopped (SIGSTOP) when its first rows arrive: no frame comes for the
    timeout, so the watchdog kills it and the error names the timeout and the time reached."""
    import os
    import signal

    hosts = _stopping_popen(monkeypatch, "first rows")
    (tmp_path / "hour.toml").write_text(DISCARD.format(stop=3600.0).replace("1e306", "0.3"))
    got = []

    def sink(block):
        if not got:
            os.kill(hosts[0].pid, signal.SIGSTOP)
        got.append(block)

    with pytest.raises(CMasterError, match=r"C master: no output for 1 s at t = \d+(\.\d+)? s: "
                                           r"the host was stopped") as caught:
        run_c_master(load_scenario(tmp_path / "hour.toml"), native_dir, sink, timeout_s=1.0)
    assert hosts[0].returncode == -signal.SIGKILL
    rows = sum(block.size for block in got)
    assert 0 < rows < 3_600_001 and caught.value.time_s == pytest.approx(rows * 0.001)


def test_the_cli_stops_a_hung_host_and_leaves_the_folder(native_dir, tmp_path, capsys, monkeypatch):
    import signal

    hosts = _stopping_popen(monkeypatch, "spawned")
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("kept")
    fails(capsys, ["run", "heavy-pi", "--fmus", str(native_dir), "--master", "c", "--timeout",
                   "1", "--out", str(out), "--format", "csv"],
          "scenario heavy-pi: C master: no output for 1 s at t = 0 s")
    assert [p.name for p in out.iterdir()] == ["keep.txt"]
    assert [host.returncode for host in hosts] == [-signal.SIGKILL]
    fails(capsys, ["run", "heavy-pi", "--fmus", str(native_dir), "--timeout", "1", "--out",
                   str(out)], "--timeout applies to the C master (--master c)")


@pytest.mark.parametrize("compiler", ["gcc", "mingw-w64"])
def test_the_loop_host_builds_without_a_warning_even_pedantic(compiler, tmp_path):
    """loop_host.c with -Wall -Wextra -Wpedantic -Werror: gcc (linux64) and mingw-w64 (win64)."""
    import subprocess

    from sma_fmu.fmi.c_common import include_flags
    from sma_fmu.fmi.hosts import HOSTS, c_compiler, windows_compiler
    from system_needs import need

    need(compiler)
    command = windows_compiler() if compiler == "mingw-w64" else c_compiler()
    built = subprocess.run([*command, "-std=c11", "-O2", "-Wall", "-Wextra", "-Wpedantic", "-Werror",
                            *include_flags(HOSTS), "-o", str(tmp_path / "loop_host.out"),
                            str(HOSTS / "loop_host.c"),
                            *([] if compiler == "mingw-w64" else ["-ldl"])],
                           capture_output=True, text=True, timeout=300)
    assert built.returncode == 0, built.stderr
