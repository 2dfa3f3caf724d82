"""The closed loop in system-level tools, run for real and checked against the library loop.

The SSP package runs in libcosim (libcosimpy) and in Ecos (ecospy), which couple by
Jacobi; the container FMU runs in fmpy and in libcosim, sequential inside (Gauss-Seidel);
both run in sma-fmu's C host, a C program on libcosim's C API (nothing preloaded: the
FMUs load libpython themselves). Each run must match the library loop of its coupling to 1e-9 in every
time-series column. The scenarios are shortened to 2.2 s (RMSE from 2 s on), with a load
step at 0.6 s.
"""
import contextlib
import dataclasses
import io
import json
import math
import os
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy.ssp.ssd import read_ssd

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios
from sma_fmu.fmi.driving.instance import FmuInstance
from sma_fmu.files.package_data import default_parameter_file
from sma_fmu.runtime.signals import load_from_table
from sma_fmu.systems.c_host import run_c_host
from sma_fmu.systems.closed_loop import closed_loop
from sma_fmu.systems.comparison import compare_hosts, deviation, rmse_table
from sma_fmu.systems.container import build_container
from sma_fmu.systems.hosts import STATE_COLUMNS
from sma_fmu.systems.packed import fmu_defaults
from sma_fmu.systems.ssp import NAMESPACES, SSD_NAME, write_ssp

TOLERANCE = 1e-9
LOAD_STEP = load_from_table({"times_s": [0.0, 0.6], "values_kg": [0.0032, 0.15]})


def short(name, stop_time_s=2.2, load=LOAD_STEP):
    scenario = load_scenario(resolve_scenarios([name])[0])
    return dataclasses.replace(scenario, stop_time_s=stop_time_s, load=load or scenario.load)


@pytest.fixture(scope="module")
def adaptive(fmu_dir, tmp_path_factory):
    """The paper's adaptive loop, 2.2 s, load step at 0.6 s: its SSP and its container."""
    scenario = short("load-step-pi+ff-adaptive")
    folder = tmp_path_factory.mktemp("adaptive")
    system = closed_loop(scenario, fmu_dir)
    return scenario, {"ssp": write_ssp(system, folder / "adaptive.ssp"),
                      "container": build_container(system, folder / "adaptive.fmu")}


def test_jacobi_loop_delays_the_pi_and_the_plant_by_one_step():
    scenario = short("heavy-pi+ff-fixed", stop_time_s=1.0)
    gauss_seidel = run_library(scenario).data
    assert deviation(gauss_seidel, run_library(scenario, "gauss-seidel").data) == 0.0
    jacobi = run_library(scenario, "jacobi").data
    # the plant applies at step k what the PI computed at k-1 from the compensator's u_ff,k-2
    expected = np.maximum(0.0, jacobi["P_ff"][:-3] + jacobi["P_fb"][1:-2])
    assert np.array_equal(jacobi["P"][2:-1], expected)
    assert np.array_equal(gauss_seidel["P"][:-1],
                          np.maximum(0.0, gauss_seidel["P_ff"] + gauss_seidel["P_fb"])[:-1])
    assert np.max(np.abs(jacobi["R"] - gauss_seidel["R"])) > 1e-3
    with pytest.raises(ValueError, match="coupling must be one of gauss-seidel, jacobi, got 'seidel'"):
        run_library(scenario, "seidel")


def _bindings(root):
    values = {}
    for component in root.iter(f"{{{NAMESPACES['ssd']}}}Component"):
        for parameter in component.iter(f"{{{NAMESPACES['ssv']}}}Parameter"):
            values[(component.get("name"), parameter.get("name"))] = parameter[0].get("value")
    return values


def test_ssp_wires_the_loop_and_binds_the_scenario_and_the_wire(fmu_dir, tmp_path):
    wire = default_parameter_file().read_text()
    assert "R_P = { value = 33.0," in wire
    (tmp_path / "wire.toml").write_text(wire.replace("R_P = { value = 33.0,", "R_P = { value = 33.5,"))
    text = resolve_scenarios(["heavy-pi"])[0].read_text().replace(
        "[scenario]", '[scenario]\nmodel = "wire.toml"', 1)
    (tmp_path / "mine-pi.toml").write_text(text.replace("[plant]", "[plant]\nT_start_degC = 24.0"))
    scenario = load_scenario(tmp_path / "mine-pi.toml")
    assert scenario.params.R_P == 33.5
    path = write_ssp(closed_loop(scenario, fmu_dir), tmp_path / "mine-pi.ssp")
    assert read_ssd(str(path)).name == "mine_pi"  # valid against the SSP 1.0 schemas
    with zipfile.ZipFile(path) as archive:
        root = ET.fromstring(archive.read(SSD_NAME))
        assert sorted(archive.namelist()) == [SSD_NAME, "resources/SmaActuator.fmu",
                                              "resources/SmaPiController.fmu",
                                              "resources/SmaScenarioSignals.fmu"]
    connections = {(c.get("startElement"), c.get("startConnector"), c.get("endElement"),
                    c.get("endConnector")) for c in root.iter(f"{{{NAMESPACES['ssd']}}}Connection")}
    assert connections == {("signals", "R_ref", "pi", "R_ref"), ("signals", "load", "plant", "load"),
                           ("pi", "P", "plant", "P_in"), ("plant", "R", "pi", "R")}
    bindings = _bindings(root)
    assert bindings[("plant", "R_P")] == "33.5"
    assert bindings[("plant", "T_start")] == "24.0"
    assert bindings[("plant", "hysteresis_mode")] == "2"  # switch
    assert bindings[("pi", "Kp")] == repr(scenario.controller.Kp)
    assert ("signals", "load_profile") not in bindings  # a String: only the packed default
    with zipfile.ZipFile(path) as archive, \
            zipfile.ZipFile(io.BytesIO(archive.read("resources/SmaScenarioSignals.fmu"))) as fmu:
        assert fmu_defaults(fmu).value("load_profile") == '{"times_s":[0.0],"values_kg":[0.25]}'
    inputs = {c.get("name") for c in root.iter(f"{{{NAMESPACES['ssd']}}}Connector")
              if c.get("kind") == "input"}
    assert "P_ff" not in inputs  # no compensator, and no unconnected input connector


def test_each_fmu_is_read_once_for_the_ssp_and_the_container(fmu_dir, tmp_path, monkeypatch):
    import fmpy

    from sma_fmu.fmi.driving.description import described
    from sma_fmu.fmi.loop import system as loop_module

    loop_module._read_fmu.cache_clear()   # earlier tests read these files already,
    described.cache_clear()               # and the description each read is kept once per file
    reads, read = [], fmpy.read_model_description
    monkeypatch.setattr(fmpy, "read_model_description",
                        lambda filename, *args, **kwargs: reads.append(Path(filename).name)
                        or read(filename, *args, **kwargs))
    system = closed_loop(short("heavy-pi+ff-fixed", stop_time_s=0.5), fmu_dir)
    write_ssp(system, tmp_path / "loop.ssp")
    build_container(system, tmp_path / "loop.fmu")
    assert sorted(reads) == sorted(f"{component.model}.fmu" for component in system.components)
    assert len(reads) == 4


def test_every_host_matches_the_library_loop_of_its_coupling(adaptive, fmu_dir):
    scenario, artifacts = adaptive
    rows = compare_hosts(scenario, fmu_dir, artifacts=artifacts)
    by_run = {row["run"]: row for row in rows if row["run"] != "library"}
    assert set(by_run) == {"libcosim (ssp)", "ecos (ssp)", "fmpy (container)",
                           "libcosim-container (container)"}
    for row in by_run.values():
        assert row["deviation"] <= TOLERANCE, row
    assert by_run["libcosim (ssp)"]["coupling"] == by_run["ecos (ssp)"]["coupling"] == "jacobi"
    assert by_run["fmpy (container)"]["coupling"] == "gauss-seidel"
    library = {row["coupling"]: row["rmse_ohm"] for row in rows if row["run"] == "library"}
    assert abs(library["jacobi"] - library["gauss-seidel"]) > 1e-6  # the couplings differ
    assert "| load-step-pi+ff-adaptive | " in rmse_table(rows)


def test_pi_controller_ssp_has_no_compensator_and_matches_in_both_ssp_hosts(fmu_dir):
    scenario = short("heavy-pi", load=None)
    rows = compare_hosts(scenario, fmu_dir, hosts=("libcosim", "ecos"))
    assert [row["deviation"] <= TOLERANCE for row in rows] == [True] * 4


def test_every_host_fails_on_a_feedforward_system_without_its_compensator(fmu_dir, tmp_path):
    """A loop with feedforward must give its compensator's outputs: none is taken as 0 W."""
    from sma_fmu.systems import hosts
    from sma_fmu.fmi.loop.wiring import loop_outputs

    system = closed_loop(short("heavy-pi", stop_time_s=0.01, load=None), fmu_dir)
    ssp, container = write_ssp(system, tmp_path / "pi.ssp"), build_container(system, tmp_path / "pi.fmu")
    expected = loop_outputs(feedforward=True)
    assert expected["P_ff"] == ("compensator", "P_ff")
    runs = [(lambda: hosts.run_ssp_libcosim(ssp, 10, expected), "has no variable compensator.P_ff"),
            (lambda: hosts.run_ssp_ecos(ssp, 1e-3, 10, expected), "cannot read compensator::P_ff"),
            (lambda: hosts.run_container_fmpy(container, 1e-3, 10, expected), "has no output P_ff"),
            (lambda: hosts.run_container_libcosim(container, 1e-3, 10, expected),
             "has no variable loop.P_ff")]
    for run, message in runs:
        with pytest.raises(hosts.HostError, match=message):
            run()


def test_ecos_leaves_no_copy_of_the_ssp_behind(fmu_dir, tmp_path, monkeypatch):
    """Ecos unpacks each SSP under TMPDIR and never removes it (2.9 MB a run): the run gives
    it a folder of its own, gone afterwards, and TMPDIR as it was; a failed run too."""
    from sma_fmu.systems import hosts
    from sma_fmu.fmi.loop.wiring import loop_outputs

    system = closed_loop(short("heavy-pi", stop_time_s=0.01, load=None), fmu_dir)
    ssp = write_ssp(system, tmp_path / "pi.ssp")
    temporary = tmp_path / "tmp"
    temporary.mkdir()
    monkeypatch.setenv("TMPDIR", str(temporary))
    samples = hosts.run_ssp_ecos(ssp, 1e-3, 10, loop_outputs(feedforward=False))
    assert len(samples["R"]) == 11
    with pytest.raises(hosts.HostError):
        hosts.run_ssp_ecos(ssp, 1e-3, 10, loop_outputs(feedforward=True))
    assert list(temporary.iterdir()) == [] and os.environ["TMPDIR"] == str(temporary)


def test_libcosim_records_the_saturated_flag_and_leaves_no_log_behind(fmu_dir, tmp_path, monkeypatch):
    """libcosim logs the Boolean ``saturated`` through a file observer into a folder of the
    run's own: on a loop whose compensator saturates (from step 1001 on), the flags equal
    the library's Jacobi loop, and nothing is left in TMPDIR; after a failed run either."""
    import tempfile

    from sma_fmu.systems import hosts
    from sma_fmu.systems.runs import run_host

    temporary = tmp_path / "tmp"
    temporary.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(temporary))
    scenario = short("heavy-pi+ff-adaptive-reachable", stop_time_s=1.2, load=None)
    flags = run_host("libcosim", scenario, fmu_dir).data["saturated"]
    library = run_library(scenario, "jacobi").data["saturated"]
    assert 0 < library.sum() < library.size and np.array_equal(flags, library)
    assert list(temporary.iterdir()) == []
    ssp = write_ssp(closed_loop(short("heavy-pi", stop_time_s=0.01, load=None), fmu_dir),
                    tmp_path / "pi.ssp")
    with pytest.raises(hosts.HostError, match="has no variable compensator.saturated"):
        hosts.run_ssp_libcosim(ssp, 10, {"saturated": ("compensator", "saturated")})
    assert list(temporary.iterdir()) == []


@pytest.mark.skipif(not Path("/proc/self/fd").is_dir(), reason="needs /proc/self/fd")
def test_an_error_after_a_libcosim_run_leaves_its_log_closed_and_removed(fmu_dir, tmp_path,
                                                                         monkeypatch):
    """libcosim closes the file observer's CSV only when the execution and the observer are
    both gone: an error raised after the steps (its traceback keeping the frames) must not
    keep them, or the file stays open in a removed folder (and cannot be removed on Windows)."""
    import tempfile

    from sma_fmu.systems import hosts

    temporary = tmp_path / "tmp"
    temporary.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(temporary))
    ssp = write_ssp(closed_loop(short("heavy-pi+ff-adaptive", stop_time_s=0.2), fmu_dir),
                    tmp_path / "ff.ssp")

    def fail(*args):
        raise RuntimeError("after the steps")
    monkeypatch.setattr(hosts, "_libcosim_samples", fail)
    with pytest.raises(RuntimeError, match="after the steps") as raised:  # keeps the traceback
        hosts.run_ssp_libcosim(ssp, 200, {"saturated": ("compensator", "saturated"),
                                          "R": ("plant", "R")})
    assert raised.traceback[-1].name == "fail"
    open_files = []
    for fd in os.listdir("/proc/self/fd"):
        with contextlib.suppress(OSError):
            open_files.append(os.readlink(f"/proc/self/fd/{fd}"))
    assert [name for name in open_files if str(temporary) in name] == []
    assert list(temporary.iterdir()) == []


def test_fmpy_simulate_ssp_runs_the_loop_from_zero_inputs(adaptive, fmu_dir):
    """As docs/systems.md says: fmpy's simulate_ssp feeds 0.0 into every input at t = 0;
    the compensator takes R_ref = 0 ohm as no reference yet, with one warning."""
    from fmpy.ssp.simulation import simulate_ssp

    result = simulate_ssp(str(adaptive[1]["ssp"]), stop_time=0.01, step_size=1e-3)
    assert result["compensator.P_ff"][0] == 0.0 and result["compensator.P_ff"][1] > 0.0
    with FmuInstance(closed_loop(adaptive[0], fmu_dir).component("compensator").fmu, "ff") as fmu:
        for k in range(2):
            fmu.set_real(("R_ref",), (0.0,))
            fmu.step(k * 1e-3, 1e-3)
        assert fmu.get_real(("P_ff",)) == [0.0]
        assert [status for status, _ in fmu.messages if status != "ok"] == ["warning"]


def test_container_and_ssp_run_in_the_c_host(adaptive, tmp_path, monkeypatch):
    """A C program on libcosim's C API, with nothing preloaded (the FMUs load libpython);
    it destroys what it made, so libcosim's unpacked copies (TMPDIR/libcosim_*) go too."""
    scenario, artifacts = adaptive
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    n = scenario.steps
    last = {coupling: run_library(scenario, coupling).data[-1] for coupling in ("gauss-seidel", "jacobi")}
    container = run_c_host("fmu", artifacts["container"], scenario.step_s, n)
    for name in STATE_COLUMNS:
        assert container[f"fmu.{name}"] == pytest.approx(last["gauss-seidel"][name], abs=TOLERANCE)
    assert container["fmu.load"] == 0.15  # after the load step
    system = run_c_host("ssp", artifacts["ssp"], scenario.step_s, n)
    assert system["plant.R"] == pytest.approx(last["jacobi"]["R"], abs=TOLERANCE)
    assert system["plant.T"] == pytest.approx(last["jacobi"]["T"], abs=TOLERANCE)
    assert system["signals.R_ref"] == pytest.approx(last["jacobi"]["R_ref"], abs=TOLERANCE)
    assert not list(tmp_path.glob("libcosim_*"))


def test_container_declares_the_units_of_its_outputs(adaptive):
    from fmpy import read_model_description

    outputs = {v.name: v.unit for v in read_model_description(str(adaptive[1]["container"])).modelVariables
               if v.causality == "output" and v.type == "Real"}
    assert outputs["R"] == "ohm" and outputs["P"] == "W" and outputs["T"] == "degC"
    assert set(outputs) >= {"R", "R_ref", "P", "T", "load"} and all(outputs.values())


def test_deviation_sees_any_column():
    data = run_library(short("heavy-pi", stop_time_s=0.05, load=None)).data
    changed = data.copy()
    changed["T_ref"][3] = 1.0  # nan in the library (no compensator)
    assert deviation(data, data) == 0.0 and deviation(data, changed) == math.inf
    changed = data.copy()
    changed["xi_F"][-1] += 1e-6
    assert deviation(data, changed) == pytest.approx(1e-6)


def test_run_paths_write_the_usual_results(fmu_dir, tmp_path):
    from sma_fmu.cli import main

    text = resolve_scenarios(["load-step-pi+ff-fixed"])[0].read_text()
    scenario_file = tmp_path / "short-fixed.toml"
    scenario_file.write_text(text.replace("stop_time_s = 30.0", "stop_time_s = 2.5"))
    scenario = load_scenario(scenario_file)
    for path, coupling in (("ssp", "jacobi"), ("container", "gauss-seidel")):
        out = tmp_path / path
        assert main(["run", str(scenario_file), "--path", path, "--fmus", str(fmu_dir),
                     "--figures", "--out", str(out)]) == 0
        folder = out / "short-fixed"
        assert {p.name for p in folder.iterdir()} == {"timeseries.csv", "metrics.json", "figure.png"}
        library = scenario_metrics(run_library(scenario, coupling).data, scenario)
        written = json.loads((folder / "metrics.json").read_text())
        assert written["overall"]["rmse_ohm"] == pytest.approx(library["overall"]["rmse_ohm"],
                                                               abs=TOLERANCE)
        header = (folder / "timeseries.csv").read_text().splitlines()[0]
        assert header.startswith("t_s,R_ref_ohm,R_ohm,T_degC")
