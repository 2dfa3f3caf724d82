"""A stroke scenario through the FMUs: the C-family FMUs under the fmpy master and the C
master, and the pythonfmu family under the fmpy master, against the library path, every
column to 1e-9 (the master maps the stroke to the signals FMU's R_ref table; the plant and
the compensator are the FMUs'). The fmpy master without a C compiler maps it in Python: the
same run to the bit."""
import numpy as np
import pytest

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.master import run_fmus
from sma_fmu.cosim.stroke_table import available_program
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.files.package_data import shipped_file
from sma_fmu.systems.c_master import run_c_master
from system_needs import needs

pytestmark = needs("gcc")
COLUMNS = ("R_ref", "R", "T", "T_ref", "x", "stroke", "P_ff", "P_fb", "P", "load")


def _short_profile(tmp_path):
    """The shipped 0.5 Hz stroke profile on the Flexinol fit, 4 s, the loads stepping at 1.5
    and 3 s (a turn of the reference in each load)."""
    text = shipped_file("scenarios", "flexinol-stroke-profile-pi+ff-adaptive.toml").read_text()
    models = shipped_file("models", "flexinol_fit.toml").parent
    text = (text.replace('model = "../models/', f'model = "{models}/')
            .replace("stop_time_s = 30.0", "stop_time_s = 4.0")
            .replace("times_s = [0.0, 10.0, 20.0]", "times_s = [0.0, 1.5, 3.0]"))
    path = tmp_path / "stroke-profile-short.toml"
    path.write_text(text + "\n[analysis]\nmetrics_start_s = 0.5\n")
    return load_scenario(path)


@pytest.mark.parametrize("master", ["c", "fmpy"])
def test_the_c_family_fmus_give_the_library_paths_stroke_run(native_dir, tmp_path, master):
    scenario = _short_profile(tmp_path)
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
    scenario = _short_profile(tmp_path)
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
