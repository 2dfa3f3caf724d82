"""FMUs that document and check themselves (sma_fmu/fmi/packaging/extras.py, reference_results.py,
documentation.py, cross_check.py): every built FMU carries documentation/index.html and
its default experiment's result in the fmi-ls-ref layout; the result reproduces, agrees
with the runtime stepper, and the FMI Cross-Check tree passes fmpy's validator."""
import html
import re
import shutil
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.cross_check import validate_result
from fmpy.cross_check.validate_vendor_repo import validate_test_fmu

from cli_failure import fails
from sma_fmu.cli import main
from sma_fmu.fmi.packaging.cross_check import cross_check_platform, model_folder
from sma_fmu.fmi.packaging.extras import add_documentation_and_reference
from sma_fmu.fmi.packaging.reference_results import (LS_REF_FOLDER, MANIFEST, output_stride, read_csv_bytes,
                                       reference_check, experiment_of)
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.systems.check import check_file

LS = "{http://fmi-standard.org/fmi-ls-manifest}"


def _read(path, name):
    with zipfile.ZipFile(path) as archive:
        return archive.read(name)


def test_every_fmu_carries_its_reference_in_the_fmi_ls_ref_layout(fmus):
    for model, path in fmus.items():
        names = set(zipfile.ZipFile(path).namelist())
        assert {MANIFEST, f"{LS_REF_FOLDER}/{model}_out.csv", "documentation/index.html",
                "documentation/result.png"} <= names, model
        root = ET.fromstring(_read(path, MANIFEST))
        assert root.get(f"{LS}fmi-ls-name") == "org.fmi-standard.fmi-ls-ref"
        experiment = root.find("Experiment")
        default = read_model_description(str(path)).defaultExperiment
        assert (float(experiment.get("startTime")), float(experiment.get("stopTime")),
                float(experiment.get("stepSize"))) == (float(default.startTime),
                                                       float(default.stopTime), float(default.stepSize))
        assert experiment.find("References").get("source") == f"{model}_out.csv"
        assert root.find("Related").get("role") == "result"
        has_inputs = any(v.causality == "input" for v in read_model_description(str(path)).modelVariables)
        assert (experiment.find("Stimuli") is not None) == has_inputs
        assert (f"{LS_REF_FOLDER}/{model}_in.csv" in names) == has_inputs


@pytest.mark.parametrize("model", ["SmaActuator", "SmaFeedforward", "SmaPiController",
                                   "SmaPwmDriver", "SmaScenarioSignals"])
def test_each_fmus_reference_reproduces(fmus, model):
    status, detail = reference_check(fmus[model])
    assert status == "ok", detail
    assert "10000 steps of 0.001 s" in detail


def test_the_plants_reference_is_the_runtime_stepper_with_the_same_inputs(fmus, params):
    """An independent path: PlantStepper, inputs held over each step at their value at t_k."""
    path = fmus["SmaActuator"]
    reference = read_csv_bytes(_read(path, f"{LS_REF_FOLDER}/SmaActuator_out.csv"))
    inputs = read_csv_bytes(_read(path, f"{LS_REF_FOLDER}/SmaActuator_in.csv"))
    experiment = experiment_of(read_model_description(str(path)))
    stride, h = output_stride(experiment), experiment.step
    plant = PlantStepper(params, params.T_room, "continuous", 0.0)
    rows = [plant.outputs]
    for k in range(experiment.steps):
        t = k * h
        power = np.interp(t, inputs["time"], inputs["P_in"])
        rows.append(plant.step(power, float(np.interp(t, inputs["time"], inputs["load"])), h))
    expected = rows[::stride]
    assert reference.size == len(expected) == 1429
    for name in ("R", "T", "x", "xi_P", "P"):
        values = np.array([getattr(row, name) for row in expected])
        assert np.max(np.abs(reference[name][1:] - values[1:])) <= 1e-9 * np.max(np.abs(values)), name
    assert reference["R"].min() < 36.0 < 48.0 < reference["R"].max()   # through the transformation


def test_a_changed_reference_fails_the_check(fmus, tmp_path):
    source = fmus["SmaPwmDriver"]
    path = tmp_path / "SmaPwmDriver.fmu"
    entry = f"{LS_REF_FOLDER}/SmaPwmDriver_out.csv"
    with zipfile.ZipFile(source) as archive, zipfile.ZipFile(path, "w") as out:
        for item in archive.infolist():
            data = archive.read(item.filename)
            if item.filename == entry:
                lines = data.decode().splitlines()
                row = lines[700].split(",")   # t = 699 * 7 steps of 1 ms
                assert float(row[1]) > 0.0
                row[1] = repr(float(row[1]) * (1 + 1e-6))
                lines[700] = ",".join(row)
                data = ("\n".join(lines) + "\n").encode()
            out.writestr(item, data)
    status, detail = reference_check(path)
    assert status == "FAIL" and "P_in at t = 4.89" in detail
    lines = {result.check: result for result in check_file(path)}
    assert lines["default experiment"].status == "FAIL"


def test_index_html_names_every_variable_with_its_unit(fmus):
    for model, path in fmus.items():
        text = _read(path, "documentation/index.html").decode("utf-8")
        rows = {}
        for row in re.findall(r"<tr>(.*?)</tr>", text, flags=re.S):
            cells = [html.unescape(cell) for cell in re.findall(r"<td>(.*?)</td>", row, flags=re.S)]
            if len(cells) == 7:
                rows[cells[0]] = cells
        description = read_model_description(str(path))
        for variable in description.modelVariables:
            assert variable.name in rows, (model, variable.name)
            assert rows[variable.name][4] == (variable.unit or "–"), (model, variable.name)
            assert rows[variable.name][1] == variable.causality
        for heading in ("What the model is", "The wire's parameters", "Platforms",
                        "Calling sequence", "Default experiment and reference result"):
            assert f"<h2>{heading}</h2>" in text, (model, heading)
        assert '<img src="result.png"' in text and "linux64" in text
        assert _read(path, "documentation/result.png")[:8] == b"\x89PNG\r\n\x1a\n"
    assert "R_P" in _read(fmus["SmaActuator"], "documentation/index.html").decode()


def test_an_fmu_without_a_default_experiment_gets_one(fmus, tmp_path):
    path = tmp_path / "SmaPwmDriver.fmu"
    with zipfile.ZipFile(fmus["SmaPwmDriver"]) as archive, zipfile.ZipFile(path, "w") as out:
        for item in archive.infolist():
            if item.filename.startswith(("extra/", "documentation/")):
                continue
            data = archive.read(item.filename)
            if item.filename == "modelDescription.xml":
                data = re.sub(rb"\s*<DefaultExperiment[^>]*/>", b"", data)
            out.writestr(item, data)
    assert read_model_description(str(path)).defaultExperiment is None
    files = add_documentation_and_reference(path)
    experiment = read_model_description(str(path), validate=True).defaultExperiment
    assert (experiment.startTime, experiment.stopTime, experiment.stepSize) == ("0.0", "10.0", "0.001")
    assert files["stimuli"].endswith("SmaPwmDriver_in.csv")
    assert reference_check(path)[0] == "ok"
    assert _read(path, files["result"]) == _read(fmus["SmaPwmDriver"], files["result"])


def test_the_cross_check_tree_validates(fmus, tmp_path):
    source = fmus["SmaActuator"].parent
    out = tmp_path / "cross-check"
    assert main(["export", "cross-check", "--fmus", str(source), "--out", str(out)]) == 0
    platform = cross_check_platform()
    for model in fmus:
        folder = model_folder(out, platform, model)
        assert folder.parts[-6:] == ("2.0", "cs", platform, "sma-fmu", folder.parts[-2], model)
        assert validate_test_fmu(str(folder)) == []
        names = {p.name for p in folder.iterdir()}
        has_inputs = model != "SmaScenarioSignals"
        assert names == {f"{model}.fmu", f"{model}_ref.csv", f"{model}_ref.opt", "ReadMe.md",
                         "LICENSE.txt"} | ({f"{model}_in.csv"} if has_inputs else set())
        assert "MIT License" in (folder / "LICENSE.txt").read_text()
    # an importer, as the rules ask: the inputs of _in.csv, run to StopTime, compared with
    # fmpy's epsilon band around _ref.csv
    folder = model_folder(out, platform, "SmaFeedforward")
    inputs = np.genfromtxt(folder / "SmaFeedforward_in.csv", delimiter=",", names=True)
    opt = dict(line.split(", ") for line in (folder / "SmaFeedforward_ref.opt").read_text().splitlines())
    result = simulate_fmu(str(folder / "SmaFeedforward.fmu"), stop_time=float(opt["StopTime"]),
                          output_interval=float(opt["StepSize"]), input=inputs)
    reference = np.genfromtxt(folder / "SmaFeedforward_ref.csv", delimiter=",", names=True)
    assert validate_result(result, reference, 0.0, float(opt["StopTime"])) is None
    changed = reference.copy()
    changed["P_ff"] *= 1.5
    assert validate_result(result, changed, 0.0, float(opt["StopTime"])) is not None


def test_cross_check_needs_three_fmus_and_leaves_out_as_it_was(fmus, tmp_path, capsys):
    folder = tmp_path / "two"
    folder.mkdir()
    for model in ("SmaActuator", "SmaPwmDriver"):
        shutil.copy(fmus[model], folder)
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    fails(capsys, ["export", "cross-check", "--fmus", str(folder), "--out", str(out)],
          "--fmus", "2 FMU(s)", "at least 3")
    assert [p.name for p in out.iterdir()] == ["keep.txt"]
