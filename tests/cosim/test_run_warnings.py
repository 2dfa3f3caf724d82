"""``sma-fmu run`` reports the wire's data-range warning on every path: the fitted Flexinol
wire (``models/flexinol_fit.toml``, data from T_data_min = 29.8 degC) started at its room
temperature of 10 degC leaves the range its data covered. The library path (the steppers),
the fmpy master with pythonfmu FMUs and with C-family FMUs, and the C master each print
``warning: NAME: TEXT`` once and put the same text in the run's metrics.json ``warnings``;
the same run started at 70 degC, inside the range throughout, gives none."""
import json
from pathlib import Path

import pytest

from sma_fmu.cli import main
from sma_fmu.cosim.run_warnings import WARNINGS_KEPT, WarningTexts, model_text, ordered
from sma_fmu.files.package_data import shipped_file
from sma_fmu.runtime.validity import DATA_RANGE_NOTE
from sma_fmu.wire.parameter_file import load_parameters
from system_needs import needs

BASE = "flexinol-stroke-load-step-pi+ff-adaptive"   # the shipped scenario these derive from


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """(cold, warm) scenario files: the base scenario for 1 s at one load (0.2 kg), started
    at the wire's T_room (cold) or at 70 degC (warm)."""
    folder = tmp_path_factory.mktemp("warned")
    wire = shipped_file("models", "flexinol_fit.toml")
    text = (shipped_file("scenarios", f"{BASE}.toml").read_text(encoding="utf-8")
            .replace('model = "../models/flexinol_fit.toml"', f"model = {json.dumps(str(wire))}")
            .replace("stop_time_s = 30.0", "stop_time_s = 1.0")
            .replace("times_s = [0.0, 10.0, 20.0]", "times_s = [0.0]")
            .replace("values_kg = [0.1, 0.2, 0.3]", "values_kg = [0.2]"))
    assert "stop_time_s = 1.0" in text and "values_kg = [0.2]" in text and str(wire) in text
    paths = []
    for name, start in (("cold", ""), ("warm", "T_start_degC = 70.0\n")):
        path = folder / f"{name}.toml"
        path.write_text(text.replace("[plant]\n", f"[plant]\n{start}"), encoding="utf-8")
        paths.append(path)
    return paths


def _expected():
    """The warning of a start at T_room below T_data_min, written from the wire file's own
    numbers (not the runtime's function)."""
    params = load_parameters(shipped_file("models", "flexinol_fit.toml"))
    assert params.T_room < params.T_data_min   # the premise: the wire's room is below its data
    return (f"T = {params.T_room:g} degC is below validity.T_data_min = {params.T_data_min:g} "
            f"degC: {DATA_RANGE_NOTE}")


def _run_and_check(runs, out, capsys, *options):
    """Run the cold and the warm scenario with ``options``; check the console and metrics."""
    assert main(["run", *map(str, runs), "--out", str(out), "--quiet", *options]) == 0
    captured = capsys.readouterr()
    expected = _expected()
    assert "T = 10 degC is below validity.T_data_min = 29.8 degC" in expected
    printed = [line for line in (captured.out + captured.err).splitlines()
               if line.startswith("warning:")]
    assert printed == [f"warning: cold: {expected}"]
    cold = json.loads((out / "cold" / "metrics.json").read_text(encoding="utf-8"))
    warm = json.loads((out / "warm" / "metrics.json").read_text(encoding="utf-8"))
    assert cold["warnings"] == [expected]
    assert warm["warnings"] == []


def test_the_library_path_reports_the_data_range_warning(runs, tmp_path, capsys):
    _run_and_check(runs, tmp_path / "out", capsys, "--path", "library")


@needs("gcc")
def test_the_fmpy_master_relays_the_pythonfmu_fmus_warning(runs, fmus, tmp_path, capsys):
    _run_and_check(runs, tmp_path / "out", capsys, "--fmus", str(Path(fmus["SmaActuator"]).parent))


@needs("gcc")
def test_the_fmpy_master_relays_the_c_family_fmus_warning(runs, native_dir, tmp_path, capsys):
    _run_and_check(runs, tmp_path / "out", capsys, "--fmus", str(native_dir))


@needs("gcc")
def test_the_c_master_relays_its_fmus_warning(runs, native_dir, tmp_path, capsys):
    _run_and_check(runs, tmp_path / "out", capsys, "--fmus", str(native_dir), "--master", "c")


def test_a_component_lists_twenty_distinct_texts_then_counts_the_messages():
    texts = WarningTexts()
    for excursion in range(25):
        texts.add(f"T = {300 + excursion} degC rose above validity.T_max = 300 degC")
        texts.add("T = 300 degC rose above validity.T_max = 300 degC")   # a repeat: kept once
    listed = texts.texts()
    assert len(listed) == WARNINGS_KEPT + 1 == 21
    assert listed[0].startswith("T = 300 degC") and listed[19].startswith("T = 319 degC")
    assert listed[-1] == "and 5 more warning messages (not listed)"


def test_the_fmus_prefix_comes_off_and_the_plant_comes_first():
    assert model_text("SmaActuator 'plant': fmi2DoStep: T = 1 degC: x") == "T = 1 degC: x"
    assert model_text("SmaFeedforward 'f': fmi3ExitInitializationMode: a: b") == "a: b"
    assert model_text("T = 1 degC: no prefix") == "T = 1 degC: no prefix"
    found = {"compensator": WarningTexts(), "plant": WarningTexts(), "driver": WarningTexts()}
    for name, texts in found.items():
        texts.add(f"from the {name}")
        texts.add("shared")
    assert ordered(found) == ["from the plant", "shared", "from the compensator", "from the driver"]
