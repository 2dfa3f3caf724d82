"""A stroke scenario exported to the system tools: the SSP in libcosim and Ecos, the container
FMU in fmpy and libcosim, against the library loop of the host's coupling (Jacobi for the SSP,
Gauss-Seidel inside the container), to the systems' 1e-9, with the ``stroke`` record [um] of
metrics.json equal to the library's.

The stroke reaches the signals FMU as the R_ref table it maps to (a knot per step), packed as
its ``reference`` default (no SSP binds a String); the stroke column is x_0 - x of the plant's
recorded x. A container cannot start a plant that warns at initialization (the shipped stroke
scenarios start at 10 degC, below the Flexinol fit's data): that is refused by name, and the
refusal is checked against what the container does without it.
"""
import json
import zipfile

import numpy as np
import pytest

from cli_failure import fails
from sma_fmu.cli import main
from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.fmi.loop.values import component_settings
from sma_fmu.fmi.loop.wiring import loop_outputs
from sma_fmu.systems import container as container_module
from sma_fmu.systems.closed_loop import closed_loop
from sma_fmu.systems.hosts import run_container_fmpy
from sma_fmu.systems.packed import fmu_defaults
from sma_fmu.systems.runs import run_host, write_artifact
from short_stroke import short_profile
from system_needs import needs

pytestmark = needs("gcc")
TOLERANCE = 1e-9
COLUMNS = ("R_ref", "R", "T", "x", "stroke", "P", "P_ff", "load")
STROKE_KEYS = ("rmse_um", "max_abs_um", "iae_um_s")


def _same_run(data, library):
    for column in COLUMNS:
        assert np.allclose(data[column], library[column], rtol=0.0, atol=TOLERANCE,
                           equal_nan=True), column


def _run_cli(scenario, path, fmu_dir, out):
    assert main(["run", str(scenario.path), "--path", path, "--fmus", str(fmu_dir),
                 "--out", str(out)]) == 0
    return json.loads((out / scenario.name / "metrics.json").read_text())


def _same_stroke(written, library, scenario):
    expected = scenario_metrics(library, scenario)["stroke"]
    for key in STROKE_KEYS:
        assert written["stroke"][key] == pytest.approx(expected[key], rel=0, abs=1e-6), key
    assert written["stroke"]["segments_rmse_um"] == pytest.approx(
        expected["segments_rmse_um"], rel=0, abs=1e-6)


def test_a_stroke_ssp_runs_in_libcosim_and_ecos_as_the_jacobi_library_loop(fmu_dir, tmp_path):
    scenario = short_profile(tmp_path)
    jacobi = run_library(scenario, "jacobi").data
    seidel = run_library(scenario).data
    assert np.ptp(jacobi["stroke"][500:]) > 10e-3   # the wire moved through the profile
    rmse = {name: scenario_metrics(data, scenario)["stroke"]["rmse_um"]
            for name, data in (("jacobi", jacobi), ("seidel", seidel))}
    assert abs(rmse["jacobi"] - rmse["seidel"]) > 1e-3   # the couplings differ in the metric
    written = _run_cli(scenario, "ssp", fmu_dir, tmp_path / "ssp")   # libcosim
    assert written["path"] == "ssp"
    _same_stroke(written, jacobi, scenario)
    ssp = write_artifact("ssp", closed_loop(scenario, fmu_dir), tmp_path)
    with zipfile.ZipFile(ssp) as archive, \
            archive.open("resources/SmaScenarioSignals.fmu") as signals, \
            zipfile.ZipFile(signals) as fmu:
        packed = fmu_defaults(fmu)
    assert packed.value("reference") == component_settings(scenario, "signals")["reference"]
    assert packed.problems() == []
    _same_run(run_host("ecos", scenario, fmu_dir, artifact=ssp).data, jacobi)
    _same_run(run_host("libcosim", scenario, fmu_dir, artifact=ssp).data, jacobi)


def test_a_stroke_container_runs_in_fmpy_and_libcosim_as_the_library_loop(fmu_dir, tmp_path):
    scenario = short_profile(tmp_path, T_start_degC=30.0)   # inside the fit's data
    library = run_library(scenario).data
    written = _run_cli(scenario, "container", fmu_dir, tmp_path / "container")   # libcosim
    assert written["path"] == "container"
    _same_stroke(written, library, scenario)
    _same_run(run_host("fmpy", scenario, fmu_dir).data, library)


def test_a_container_whose_plant_warns_at_its_start_is_refused(fmu_dir, tmp_path, capsys,
                                                                 monkeypatch):
    scenario = short_profile(tmp_path, stop_time_s=1.0)   # the shipped start: 10 degC
    out = tmp_path / "out"
    for argv in (["run", str(scenario.path), "--path", "container", "--out", str(out)],
                 ["export", "container", str(scenario.path), "--out", str(tmp_path / "c.fmu")]):
        fails(capsys, [*argv, "--fmus", str(fmu_dir)], str(scenario.path.name),
              "validity.T_data_min = 29.8 degC", "T_start_degC", "--path ssp")
    assert not out.exists() and not (tmp_path / "c.fmu").exists()
    # what the refusal spares: the container built anyway fails its initialization in fmpy
    # (libcosim would end the process)
    monkeypatch.setattr(container_module, "container_refusal", lambda scenario: None)
    built = write_artifact("container", closed_loop(scenario, fmu_dir), tmp_path)
    with pytest.raises(Exception, match="fmi2ExitInitializationMode"):
        run_container_fmpy(built, scenario.step_s, scenario.steps,
                           loop_outputs(scenario.controller.feedforward))
