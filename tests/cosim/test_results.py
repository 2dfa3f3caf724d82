"""Results that fit any scenario, written whole or not at all, as strict JSON."""
import json
import math
import subprocess
import sys

import pytest

from sma_fmu.cli import main
from sma_fmu.cosim.scenario import default_analysis, load_scenario
from sma_fmu.files.json_output import json_text
from sma_fmu.files.package_data import shipped_file


def _copy(folder, name, text_changes=()):
    """A shipped scenario copied into ``folder`` (same file name), with text replaced."""
    text = shipped_file("scenarios", f"{name}.toml").read_text()
    for old, new in text_changes:
        assert old in text
        text = text.replace(old, new)
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}.toml"
    path.write_text(text)
    return path


def test_default_windows_follow_the_duration():
    assert default_analysis(30.0) == (2.0, 24.0, 28.0)  # the paper's choices
    short = default_analysis(1.5)
    assert short.metrics_start_s == pytest.approx(0.15)
    assert 0.0 <= short.zoom_start_s < short.zoom_end_s <= 1.5


def test_a_short_scenario_runs_and_reports(tmp_path, capsys):
    path = _copy(tmp_path / "in", "heavy-pi+ff-adaptive", [("stop_time_s = 30.0", "stop_time_s = 1.5")])
    assert main(["run", str(path), "--path", "library", "--out", str(tmp_path / "out")]) == 0
    metrics = json.loads((tmp_path / "out" / path.stem / "metrics.json").read_text())
    assert metrics["window"] == "t >= 0.15 s"
    assert metrics["overall"]["samples"] == 1351 and metrics["overall"]["rmse_ohm"] > 0
    assert all(s["rmse_ohm"] is not None for s in metrics["segments"])


def test_analysis_section_sets_the_windows(tmp_path):
    path = _copy(tmp_path, "heavy-pi")
    path.write_text(path.read_text() + "\n[analysis]\nmetrics_start_s = 5.0\n")
    scenario = load_scenario(path)
    assert scenario.analysis == (5.0, 24.0, 28.0)


def test_same_file_names_from_two_folders_do_not_overwrite(tmp_path, capsys):
    first = _copy(tmp_path / "a", "heavy-pi", [("stop_time_s = 30.0", "stop_time_s = 3.0")])
    second = _copy(tmp_path / "b", "heavy-pi", [("stop_time_s = 30.0", "stop_time_s = 3.0"),
                                                ("[controller]\n", "[controller]\nKp_W_per_ohm = 0.9\n")])
    assert main(["run", str(first), str(second), "--path", "library", "--out", str(tmp_path / "o")]) == 0
    a = json.loads((tmp_path / "o" / "a-heavy-pi" / "metrics.json").read_text())
    b = json.loads((tmp_path / "o" / "b-heavy-pi" / "metrics.json").read_text())
    assert a["overall"]["rmse_ohm"] != b["overall"]["rmse_ohm"]


def test_two_settings_of_one_controller_are_compared_by_name(tmp_path, capsys):
    changes = [("stop_time_s = 30.0", "stop_time_s = 3.0")]
    slow = _copy(tmp_path, "heavy-pi", changes)
    fast = slow.with_name("heavy-pi-fast.toml")
    fast.write_text(slow.read_text().replace("[controller]\n", "[controller]\nKp_W_per_ohm = 1.2\n"))
    assert main(["run", str(slow), str(fast), "--path", "library", "--figures",
                 "--out", str(tmp_path / "o")]) == 0
    comparison = (tmp_path / "o" / "comparison.md").read_text()
    # two runs of kind pi: labelled by their scenario names
    assert "| heavy-pi | pi |" in comparison and "| heavy-pi-fast | pi |" in comparison
    assert (tmp_path / "o" / "comparison-heavy.png").stat().st_size > 10000


def test_failed_run_leaves_the_output_folder_as_it_was(tmp_path, capsys, fmus):
    out = tmp_path / "results"
    out.mkdir()
    (out / "mine.txt").write_text("before")
    only_plant = tmp_path / "fmus"
    only_plant.mkdir()
    (only_plant / "SmaActuator.fmu").write_bytes(fmus["SmaActuator"].read_bytes())
    # heavy-pi runs (plant only), then heavy-pi+ff-fixed fails: no SmaFeedforward.fmu
    assert main(["run", "heavy-pi", "heavy-pi+ff-fixed", "--fmus", str(only_plant),
                 "--out", str(out)]) == 2
    assert "SmaFeedforward.fmu not found" in capsys.readouterr().err
    assert sorted(p.name for p in out.iterdir()) == ["mine.txt"]
    assert not any(p.name.endswith(".partial") for p in tmp_path.iterdir())


def test_failed_build_leaves_no_fmu(tmp_path, capsys):
    bad = tmp_path / "wire.toml"
    bad.write_text(shipped_file("models", "reference_wire.toml").read_text().replace(
        "R_P = { value = 33.0", "R_P = { value = 60.0"))
    assert main(["build", "--model", str(bad), "--out", str(tmp_path / "fmus")]) == 2
    assert not (tmp_path / "fmus").exists()


def test_json_never_holds_nan_or_infinity():
    text = json_text({"a": math.inf, "b": [1.0, math.nan], "c": {"d": -math.inf}})
    document = json.loads(text, parse_constant=lambda name: pytest.fail(f"{name} in JSON"))
    assert document["a"] is None and document["b"] == [1.0, None] and document["c"]["d"] is None
    assert set(document["non_finite_values"]) == {"a", "b[1]", "c.d"}


def test_importing_the_library_leaves_the_matplotlib_backend_alone():
    code = ("import matplotlib; matplotlib.use('svg')\n"
            "import sma_fmu.systems.runner, sma_fmu.identification.runner, sma_fmu.cli\n"
            "print(matplotlib.get_backend())\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "svg"


def test_outputs_get_the_usual_permissions(tmp_path):
    """Staged outputs are not left private (mkdtemp/mkstemp make 0700/0600)."""
    import os
    import stat
    from sma_fmu.files.output_folder import staged_folder, write_file
    mask = os.umask(0o022)
    try:
        with staged_folder(tmp_path / "out") as folder:
            (folder / "a.txt").write_text("a")
        write_file(tmp_path / "b.csv", "b")
    finally:
        os.umask(mask)
    assert stat.S_IMODE((tmp_path / "out").stat().st_mode) == 0o755
    assert stat.S_IMODE((tmp_path / "b.csv").stat().st_mode) == 0o644


def test_csv_blocks_are_written_as_numpy_savetxt_writes_them(tmp_path):
    """The CSV writer formats a whole block at once: the text is np.savetxt's, row by row,
    for ordinary, tiny, huge, negative and non-finite values and booleans."""
    import io

    import numpy as np

    from sma_fmu.cosim.loop import COLUMN_NAMES, COLUMNS, TIMESERIES_DTYPE
    from sma_fmu.cosim.recording import CSV_FORMAT, TimeseriesWriter

    rng = np.random.default_rng(7)
    rows = np.zeros(500, dtype=TIMESERIES_DTYPE)
    for name, _ in COLUMNS:
        if rows[name].dtype == bool:
            rows[name] = rng.random(500) < 0.5
        else:
            rows[name] = rng.normal(0.0, 1.0, 500) * 10.0 ** rng.integers(-300, 300, 500)
    first = [name for name, _ in COLUMNS if rows[name].dtype != bool][0]
    rows[first][:3] = [math.nan, math.inf, -math.inf]
    path = tmp_path / "timeseries.csv"
    writer = TimeseriesWriter(path, "csv")
    writer.write(rows[:123])
    writer.write(rows[123:])
    writer.close()
    expected = io.StringIO()
    expected.write(",".join(COLUMN_NAMES) + "\n")
    np.savetxt(expected, np.column_stack([rows[name].astype(float) for name, _ in COLUMNS]),
               delimiter=",", fmt=CSV_FORMAT)
    assert path.read_text(encoding="utf-8") == expected.getvalue()
