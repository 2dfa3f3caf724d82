"""``sma-fmu bench --only c-master``'s measurements of what the user waits for: whole commands
and a sweep. The numbers are the bench's to print; what is checked here is what they
stand on: the two commands wrote the same files, with figures or without, and the sweep's
metrics equal its points run one at a time in a fresh C master."""
import pytest

from system_needs import needs

pytestmark = needs("gcc")

SPEC = """
[study]
scenarios = ["heavy-pi", "load-step-pi+ff-adaptive"]
seed = 1
[overrides]
"scenario.stop_time_s" = 2.0
[axes]
kind = "grid"
[axes.values]
"controller.Kp_W_per_ohm" = [0.2, 1.5]
"""


def test_whole_run_commands_write_the_same_files(native_dir, tmp_path):
    from sma_fmu.bench.c_master_commands import COMMAND_TARGET, command_lines, run_command_times

    times = run_command_times(native_dir, 1, tmp_path, scenarios=("heavy-pi", "heavy-pi+ff-fixed"))
    assert set(times) == {"default, no figures", "--figures"}
    for label, row in times.items():
        assert row["same_outputs"] and row["runs"] == 1 and row["c_s"] > 0 and row["library_s"] > 0
        assert set(row["walls"]) == {"heavy-pi", "heavy-pi+ff-fixed"}
        assert row["ratio"]["median"] == pytest.approx(row["c_s"] / row["library_s"], rel=0.01)
    for path in ("c", "library"):
        assert (tmp_path / f"figures-{path}-0" / "heavy-pi" / "figure.png").is_file()
        plain = tmp_path / f"default-{path}-0"
        assert (plain / "heavy-pi" / "metrics.json").is_file() and not list(plain.rglob("*.png"))
    lines = command_lines(times)
    assert f"target <= {COMMAND_TARGET:g}" in lines[0] and "the same output files: yes" in lines[0]
    assert any(line.strip().startswith("run table's wall s, heavy-pi:") for line in lines)


def test_the_sweep_measure_checks_its_metrics_to_the_bit(native_dir, tmp_path):
    from sma_fmu.bench.c_master_commands import SWEEP_TARGET, command_lines, sweep_throughput

    spec = tmp_path / "grid.toml"
    spec.write_text(SPEC, encoding="utf-8")
    sweep = sweep_throughput(native_dir, tmp_path, workers=1, spec_path=spec, rounds=1)
    assert sweep["equal"] and sweep["runs"] == 4 and len(sweep["workers"]) == 1
    assert sweep["per_worker"] > 0 and sweep["library_per_s"] > 0 and sweep["rounds"] == 1
    assert sweep["library_task_per_s"] <= sweep["library_per_s"]   # its metrics' time on top
    assert sweep["ratio"]["min"] <= sweep["ratio"]["median"] <= sweep["ratio"]["max"]
    assert (tmp_path / "sweep" / "results.parquet").is_file()
    first, second = command_lines({}, sweep)[-2:]
    assert f"target >= {SWEEP_TARGET:g}" in first and "to the bit: yes" in second
