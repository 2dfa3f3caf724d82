"""`sma-fmu bench --only inverse` (sma_fmu/bench/inverse.py) measures and reports both wires:
one inversion in Python and C, and the closed loop through each wire's FMUs. Speed is never
asserted: only that every case ran, on the wire it names, and is reported; a one-stage
--model is refused by name, the output folder left as it was."""
import json
import math

from sma_fmu.cli import main
from sma_fmu.files.package_data import default_parameter_file
from sma_fmu.wire.parameter_file import load_parameters
from system_needs import needs


@needs("gcc")
def test_the_inverse_section_reports_both_wires(tmp_path, capsys):
    out = tmp_path / "bench"
    assert main(["bench", "--only", "inverse", "--runs", "1", "--stop-time", "0.2",
                 "--out", str(out)]) == 0
    section = json.loads((out / "benchmark.json").read_text())["inverse"]
    assert set(section["per_inversion"]) == {"reference", "two-stage"}
    for cost in section["per_inversion"].values():
        assert math.isfinite(cost["python_ns"]) and cost["python_ns"] > 0 and cost["c_ns"] > 0
    walls = section["walls_s"]
    assert set(walls) == {"reference", "two-stage"} and all(len(w) == 1 for w in walls.values())
    assert section["stop_time_s"] == 0.2
    # the default two-stage wire is the reference wire with a second stage, built into FMUs
    wire = load_parameters(section["model"])
    assert wire.terms.two_stage and wire.terms.w2 == 0.475
    assert wire.R_P == load_parameters().R_P
    assert all((out / f"fmus-{name}" / "SmaFeedforward.fmu").is_file() for name in walls)
    text = capsys.readouterr().out
    assert "two-stage / reference" in text and "one inversion at 0.25 kg" in text
    cpu = section["cpu_ratio"]
    assert cpu["min"] <= cpu["median"] <= cpu["max"] and set(section["cpu_s"]) == set(walls)
    assert len(section["load_average"]) == 2


def test_a_one_stage_model_is_refused_by_name(tmp_path, capsys):
    out = tmp_path / "bench"
    model = default_parameter_file()
    assert main(["bench", "--only", "inverse", "--model", str(model), "--out", str(out)]) == 2
    error = capsys.readouterr().err.strip()
    assert error.startswith("sma-fmu: error: --model") and str(model) in error
    assert "second_stage.w2 = 0" in error and "\n" not in error
    assert not out.exists()
