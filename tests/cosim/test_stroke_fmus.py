"""A stroke scenario through the FMUs: the C-family FMUs under the fmpy master and the C
master, the pythonfmu family under the fmpy master, and the FMI 3.0 FMUs with event mode
(``--events``), against the library path, every column to 1e-9 (the master maps the stroke
to the signals FMU's R_ref table; the plant, the driver and the compensator are the FMUs').
The fmpy master without a C compiler maps it in Python: the same run to the bit."""
import json

import numpy as np
import pytest

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.master import run_fmus
from sma_fmu.cosim.stroke_table import available_program
from sma_fmu.cli import main
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.systems.c_master import run_c_master
from short_stroke import short_profile
from system_needs import needs

pytestmark = needs("gcc")
COLUMNS = ("R_ref", "R", "T", "T_ref", "x", "stroke", "P_ff", "P_fb", "P", "load")


@pytest.mark.parametrize("master", ["c", "fmpy"])
def test_the_c_family_fmus_give_the_library_paths_stroke_run(native_dir, tmp_path, master):
    scenario = short_profile(tmp_path)
    library = run_library(scenario).data
    run = run_c_master if master == "c" else run_fmus
    fmus = run(scenario, native_dir).data
    assert len(fmus) == len(library) == scenario.steps + 1
    for column in COLUMNS:
        assert np.allclose(fmus[column], library[column], rtol=0.0, atol=1e-9,
                           equal_nan=True), column
    assert np.ptp(library["stroke"][500:]) > 10e-3   # the wire moved through the profile
    ours, theirs = (scenario_metrics(data, scenario)["stroke"] for data in (fmus, library))
    assert ours["rmse_um"] == pytest.approx(theirs["rmse_um"], abs=1e-3)


def test_the_pythonfmu_family_gives_the_library_paths_stroke_run(fmus, tmp_path, monkeypatch):
    """With a C compiler the fmpy master maps the stroke in C; without one (a machine with
    the pythonfmu family only) in Python: the same run to the bit, both the library's."""
    scenario = short_profile(tmp_path)
    library = run_library(scenario).data
    assert available_program() is not None
    python_family = run_fmus(scenario, fmus["SmaActuator"].parent).data
    for column in COLUMNS:
        assert np.allclose(python_family[column], library[column], rtol=0.0, atol=1e-9,
                           equal_nan=True), column
    monkeypatch.setenv("CC", str(tmp_path / "no-such-cc"))   # part of the program's key
    assert available_program() is None
    without = run_fmus(scenario, fmus["SmaActuator"].parent).data
    assert without.tobytes() == python_family.tobytes()


def test_event_mode_gives_the_library_paths_stroke_run(fmi3_fmus, tmp_path):
    """``--events``: the driver (current limit, no wave: no early return) and the plant in
    FMI 3.0 event mode; row k's P is the plant's energy over the step / h, so P may differ
    from the library's in the last bits; the stroke record in metrics.json is the library's."""
    scenario = short_profile(tmp_path)
    library = run_library(scenario).data
    out = tmp_path / "events"
    assert main(["run", str(scenario.path), "--fmus", str(fmi3_fmus["SmaActuator"].parent),
                 "--events", "--out", str(out)]) == 0
    written = json.loads((out / scenario.name / "metrics.json").read_text())
    assert written["events"] is True
    assert np.ptp(library["stroke"][500:]) > 10e-3   # the wire moved through the profile
    theirs = scenario_metrics(library, scenario)["stroke"]
    for key in ("rmse_um", "max_abs_um", "iae_um_s"):
        assert written["stroke"][key] == pytest.approx(theirs[key], rel=0, abs=1e-6), key
    events = run_fmus(scenario, fmi3_fmus["SmaActuator"].parent, events=True).data
    for column in COLUMNS:
        assert np.allclose(events[column], library[column], rtol=0.0, atol=1e-9,
                           equal_nan=True), column
