"""The benchmark script runs and reports every section (speed is never asserted here)."""
import json

import pytest

from sma_fmu.cli import main
from system_needs import needs


@needs("gcc")  # the C hosts and the native floor FMU
def test_benchmark_runs_and_reports_every_section(tmp_path, capsys):
    assert main(["bench", "--runs", "1", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    for text in ("FMU per step", "Trivial (baseline)", "load-step, 30 s at 1 ms",
                 "pi+ff-adaptive (fmu)", "pi+ff-adaptive (library)", "library batch",
                 "identification, 4 loads", "target", "SmaActuator in C hosts",
                 "plain C host, front (after)", "libcosim step, front (after)",
                 "plain C host, front without fast path", "Ratios (median of 1 alternating runs",
                 "FMU closed loop / library path, pi+ff-adaptive",
                 "SmaActuator in the C host / library plant step",
                 "SmaActuator in the fmpy master / library plant step",
                 "native C FMU in the C host / library plant step",   # a C compiler is there
                 "SmaActuator / native C FMU, C host", "SmaActuator / native C FMU, fmpy master"):
        assert text in out
    results = json.loads((tmp_path / "benchmark.json").read_text())
    assert set(results["fmu_step"]) == {"SmaActuator", "SmaFeedforward", "Trivial (baseline)"}
    assert len(results["closed_loop_load_step_30s"]) == 6
    for row in results["closed_loop_load_step_30s"].values():   # the table is consistent
        assert row["min_s"] <= row["wall_s"] <= row["max_s"]
        assert row["real_time_factor"] == pytest.approx(30.0 / row["wall_s"], abs=0.051)
        assert len(row["walls_s"]) == 1
    for row in results["ratios"].values():   # every ratio with its spread
        assert row["min"] <= row["median"] <= row["max"] and row["runs"] == 1
    assert results["floor"]["not_built"] is None
    assert results["identification_4_loads_s"] < 60.0   # a finished fit, not a placeholder
    c_hosts = results["c_host_step"]
    assert len(c_hosts) == 6 and all(0 < row["p50_us"] <= row["p99_9_us"] for row in c_hosts.values())


def test_the_c_host_bench_steps_the_plant_at_the_library_steps_load(fmi_host_exe, unpacked, fmus):
    """Issue 27: the C host's SmaActuator ran at load 0 against a library step at 0.05 kg."""
    from fmi_host import FmiHost
    from sma_fmu.bench.c_hosts import BENCH_LOAD_KG, _references, plain_host_commands
    refs = _references(fmus["SmaActuator"])
    commands = plain_host_commands(refs, steps=10)
    timed = [line for line in commands if line.startswith("bench ")]
    assert len(timed) == 1
    with FmiHost(fmi_host_exe, unpacked["SmaActuator"]) as host:
        for line in commands[:commands.index(timed[0])]:  # up to the timed steps
            assert host.call(line).status == 0, line
        assert [float(v) for v in host.call(f"getreal 0 1 {refs['load']}").values] == [BENCH_LOAD_KG]
        assert BENCH_LOAD_KG > 0
