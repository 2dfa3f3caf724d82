"""Long runs (issue 29): an output interval, results streamed in bounded memory, Parquet.

The metrics count every step whatever is recorded; the streamed metrics are those of the
whole series; a run's peak memory does not grow with its length; Parquet and CSV read back.
"""
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from sma_fmu.cli import main
from sma_fmu.cosim.loop import COLUMN_NAMES, COLUMNS, ROWS_PER_CHUNK, TIMESERIES_DTYPE, run_library
from sma_fmu.cosim.metrics import StreamingMetrics, scenario_metrics, unreachable_intervals, unreachable_samples
from sma_fmu.cosim.recording import FigureSeries, RunRecorder, interval_steps, read_timeseries
from sma_fmu.cosim.scenario import ScenarioError, load_scenario, resolve_scenarios
from sma_fmu.files.package_data import shipped_file

SCENARIO = "load-step-pi+ff-adaptive"


def _scenario_file(tmp_path, stop_time_s, extra="", name=SCENARIO):
    """The shipped scenario with another stop time (and ``extra`` lines in [scenario])."""
    text = shipped_file("scenarios", f"{name}.toml").read_text(encoding="utf-8")
    lines = []
    for line in text.splitlines():
        if line.startswith("stop_time_s"):
            line = f"stop_time_s = {stop_time_s}\n{extra}"
        elif line.startswith("model"):
            line = f"model = {str(shipped_file('models', 'reference_wire.toml'))!r}"
        lines.append(line)
    path = tmp_path / f"{name}-{stop_time_s:g}.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _metrics(folder):
    metrics = json.loads(next(folder.glob("*/metrics.json")).read_text())
    metrics.pop("wall_time_s")
    return metrics


@pytest.mark.parametrize("path", ["library", "fmu"])
def test_metrics_with_and_without_an_output_interval_agree_exactly(tmp_path, fmus, path):
    fmu_dir = str(fmus["SmaActuator"].parent)
    every, sparse = tmp_path / "every", tmp_path / "sparse"
    assert main(["run", SCENARIO, "--path", path, "--fmus", fmu_dir, "--out", str(every)]) == 0
    assert main(["run", SCENARIO, "--path", path, "--fmus", fmu_dir, "--out", str(sparse),
                 "--output-interval", "0.05", "--format", "parquet"]) == 0
    assert _metrics(every) == _metrics(sparse)
    full = read_timeseries(next(every.glob("*/timeseries.csv")))
    thin = read_timeseries(next(sparse.glob("*/timeseries.parquet")))
    assert len(full) == 30001 and len(thin) == 601
    assert list(thin.columns) == list(full.columns)
    np.testing.assert_allclose(thin["t_s"], np.arange(601) * 0.05, rtol=0, atol=1e-12)
    # every 50th step, the CSV's 10 digits against Parquet's every bit
    np.testing.assert_allclose(thin["R_ohm"], full["R_ohm"][::50].to_numpy(), rtol=1e-9)


def test_streamed_metrics_are_those_of_the_whole_series(tmp_path):
    scenario = load_scenario(resolve_scenarios([SCENARIO])[0])
    blocks = []
    result = run_library(scenario, sink=lambda block: blocks.append(block.copy()))
    assert result.data is None and {len(b) for b in blocks[:-1]} == {ROWS_PER_CHUNK}
    whole = run_library(scenario).data
    joined = np.concatenate(blocks)
    for name in whole.dtype.names:  # field by field: NaN equals NaN there
        np.testing.assert_array_equal(joined[name], whole[name])
    streamed = StreamingMetrics(scenario)
    for block in blocks:
        streamed.update(block)
    assert streamed.result() == scenario_metrics(whole, scenario)
    # against the whole-array formulas (an independent second computation)
    window = whole["t"] >= scenario.analysis.metrics_start_s - 1e-9 * scenario.step_s
    error = (whole["R"] - whole["R_ref"])[window]
    overall = streamed.result()["overall"]
    assert overall["rmse_ohm"] == pytest.approx(math.sqrt(np.mean(error ** 2)), rel=1e-13)
    assert overall["max_abs_ohm"] == np.max(np.abs(error))
    assert overall["samples"] == error.size


def test_unreachable_intervals_join_across_blocks():
    scenario = load_scenario(resolve_scenarios([SCENARIO])[0])
    n = 3 * ROWS_PER_CHUNK + 17
    data = np.zeros(n, dtype=TIMESERIES_DTYPE)
    data["t"] = np.arange(n) * scenario.step_s
    data["load"] = 0.05
    data["R_ref"] = 45.0
    unreachable = (np.arange(n) > ROWS_PER_CHUNK - 100) & (np.arange(n) < 2 * ROWS_PER_CHUNK + 50)
    data["R_ref"][unreachable] = 1.0  # far below the fully hot resistance
    data["R"] = data["R_ref"] + 0.5
    below, above = unreachable_samples(data["R_ref"], data["load"], scenario.params)
    expected = unreachable_intervals(data["t"], below, above)
    assert len(expected) == 1
    assert scenario_metrics(data, scenario)["unreachable_intervals_s"] == expected


def test_figure_rows_stay_bounded_and_evenly_spaced():
    series = FigureSeries(limit=1000)
    rows = np.zeros(10_007, dtype=TIMESERIES_DTYPE)
    rows["t"] = np.arange(rows.size)
    for first in range(0, rows.size, 333):
        series.add(rows[first:first + 333])
    kept = series.rows()
    assert kept.size <= 2 * 1000 + 1 and kept["t"][-1] == rows.size - 1
    steps = np.diff(kept["t"][:-1])
    assert steps.min() == steps.max() == series.stride


@pytest.mark.parametrize("interval, message", [
    (0.0015, "not a whole number of steps"), (-1.0, "> 0"), (math.inf, "> 0")])
def test_an_output_interval_off_the_grid_is_refused(interval, message):
    with pytest.raises(ValueError, match=message):
        interval_steps(interval, 1e-3)


def test_a_scenario_key_sets_the_interval_and_a_bad_one_names_file_and_key(tmp_path):
    good = load_scenario(_scenario_file(tmp_path, 5.0, "output_interval_s = 0.1"))
    assert good.output_interval_s == 0.1
    (tmp_path / "bad").mkdir()
    bad = _scenario_file(tmp_path / "bad", 5.0, "output_interval_s = 0.00015")
    with pytest.raises(ScenarioError, match=r"\[scenario\] output_interval_s = 0.00015 s is not a whole number"):
        load_scenario(bad)
    out = tmp_path / "out"
    assert main(["run", str(_scenario_file(tmp_path, 5.0, "output_interval_s = 0.1")), "--path", "library",
                 "--out", str(out)]) == 0
    assert len(read_timeseries(next(out.glob("*/timeseries.csv")))) == 51


def test_parquet_round_trips_every_bit(tmp_path):
    scenario = load_scenario(resolve_scenarios([SCENARIO])[0])
    recorder = RunRecorder(scenario, tmp_path, every=1, fmt="parquet")
    whole = run_library(scenario).data
    recorder.feed(whole)
    recorder.close()
    frame = read_timeseries(tmp_path / "timeseries.parquet")
    assert list(frame.columns) == list(COLUMN_NAMES)
    for (name, _), label in zip(COLUMNS, COLUMN_NAMES):
        np.testing.assert_array_equal(frame[label].to_numpy(), whole[name])


# VmHWM: this process's own peak RSS [kB] (ru_maxrss would carry the parent's over exec)
_PEAK = """
import sys
from sma_fmu.cli import main
assert main(["run", sys.argv[1], "--path", "library", "--out", sys.argv[2]]) == 0
print(next(line.split()[1] for line in open("/proc/self/status") if line.startswith("VmHWM:")))
"""


def test_peak_memory_stays_flat_as_the_run_grows(tmp_path):
    """Peak RSS of a 60-s and a 900-s run (60,000 and 900,000 steps at 1 ms): a run that
    kept its series would grow by >= 840,000 rows x 121 bytes = 101 MB (the structured
    array alone); a streamed one keeps at most FIGURE_ROWS x 2 rows for its figure."""
    peaks = []
    for stop in (60.0, 900.0):
        path = _scenario_file(tmp_path, stop)
        out = tmp_path / f"out{stop:g}"
        result = subprocess.run([sys.executable, "-c", _PEAK, str(path), str(out)],
                                capture_output=True, text=True, check=True)
        peaks.append(int(result.stdout.split()[-1]) / 1024.0)  # [MiB]
        assert len(read_timeseries(next(out.glob("*/timeseries.csv")))) == stop * 1000 + 1
    assert peaks[1] - peaks[0] < 25.0, peaks


def test_parquet_in_several_row_groups_reads_back_in_order(tmp_path, monkeypatch):
    import pyarrow.parquet as pq

    from sma_fmu.cosim import recording

    monkeypatch.setattr(recording, "PARQUET_ROW_GROUP", 5000)
    scenario = load_scenario(resolve_scenarios([SCENARIO])[0])
    recorder = RunRecorder(scenario, tmp_path, every=3, fmt="parquet")
    run_library(scenario, sink=recorder)
    recorder.close()
    path = tmp_path / "timeseries.parquet"
    assert pq.ParquetFile(path).num_row_groups >= 2
    frame = read_timeseries(path)
    np.testing.assert_allclose(frame["t_s"], np.arange(10001) * 0.003, rtol=0, atol=1e-12)
