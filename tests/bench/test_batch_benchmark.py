"""sma-fmu bench --only batch --quick: the batch engine's throughput table (speed not asserted)."""
import json

from sma_fmu.cli import main


def test_batch_section_alone_prints_and_writes_the_table(tmp_path, capsys):
    assert main(["bench", "--only", "batch", "--quick", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "batch engine: closed-loop steps/s per core" in out and "at N = 1000" in out
    results = json.loads((tmp_path / "benchmark.json").read_text())["batch_engine"]
    assert set(results["sets"]) == {"mixed", "gain grid"}
    for rows in results["sets"].values():
        assert [row["N"] for row in rows] == [1, 100, 1000]
        for row in rows:
            ratio = row["batch_steps_per_s"] / row["scalar_steps_per_s"]
            assert abs(row["ratio"] - ratio) <= 0.05 + 1e-6 * ratio
