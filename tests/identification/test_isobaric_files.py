"""Isobaric files: column and unit detection, branch splitting on noisy temperature, bad files,
and the command line from a lab file to a wire parameter file the FMU builder and runner take."""
import json

import numpy as np
import pytest

from cli_failure import fails as _fails
from sma_fmu.cli import main
from sma_fmu.identification.isobaric.files import read_isobaric
from sma_fmu.identification.isobaric.synthetic import (IsobaricProgramme, isobaric_table,
                                                       isobaric_text)
from sma_fmu.files.package_data import shipped_file
from sma_fmu.wire.parameter_file import load_parameter_set
from sma_fmu.files.output_folder import MARKER


def _columns(params, load=0.15, **settings):
    programme = {"points": 1200, "seed": 3, "cycles": 2}
    programme.update(settings)
    columns, _ = isobaric_table(params, load, IsobaricProgramme(**programme), with_resistance=True)
    return columns


def _write(path, names, columns, delimiter=",", preamble=(), decimal_comma=False):
    lines = list(preamble) + [delimiter.join(names)]
    for values in zip(*columns):
        cells = [f"{v:.6f}" for v in values]
        lines.append(delimiter.join(c.replace(".", ",") if decimal_comma else c for c in cells))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_noisy_temperature_splits_into_alternating_branches(tmp_path, params):
    columns = _columns(params, noise_K=3.0, cycles=3, points=3000)
    path = tmp_path / "a.csv"
    path.write_text(isobaric_text(columns, ["load: 0.15 kg"]), encoding="utf-8")
    data = read_isobaric(path)
    # 3 K noise makes the raw temperature reverse hundreds of times within a branch ...
    assert np.count_nonzero(np.diff(np.sign(np.diff(data.temperature)))) > 500
    # ... but the branches follow the programme: heating, cooling, three times
    assert [b.direction for b in data.branches] == [1, -1] * 3
    assert [b.cycle for b in data.branches] == [1, 1, 2, 2, 3, 3]
    assert [b.level for b in data.branches] == [0, 0, 1, 1, 2, 2]
    assert data.load == 0.15 and data.columns["strain"] == ("strain_percent", "percent")


def test_columns_and_units_are_detected(tmp_path, params):
    c = _columns(params)
    kelvin = c["temperature_C"] + 273.15
    length_mm = 800.0 * (1.0 + c["strain_percent"] / 100.0)
    semicolon = _write(tmp_path / "b.csv", ["Temp [K]", "Length (mm)", "R [ohm]"],
                       [kelvin, length_mm, c["resistance_ohm"]], delimiter=";",
                       preamble=["Specimen: wire A", "Stress: 83.24 MPa"], decimal_comma=True)
    data = read_isobaric(semicolon)
    assert data.columns == {"temperature": ("Temp [K]", "K"), "length": ("Length (mm)", "mm"),
                            "resistance": ("R [ohm]", "ohm")}
    assert data.time is None and data.absolute
    assert data.load == pytest.approx(0.15, rel=1e-3)     # from the stress and the 0.15 mm wire
    np.testing.assert_allclose(data.temperature, c["temperature_C"], atol=1e-5)
    np.testing.assert_allclose(data.strain, c["strain_percent"] / 100.0, atol=1e-8)


def _bad(tmp_path, params, kind):
    c = _columns(params)
    t, e = c["temperature_C"], c["strain_percent"]
    path = tmp_path / f"{kind}.csv"
    if kind == "one-column":
        _write(path, ["temperature_C"], [t])
    elif kind == "text":
        _write(path, ["temperature_C", "strain_percent"], [t, e])
        lines = path.read_text().splitlines()
        lines[40] = "61.2,n/a"           # line 41 of the file
        path.write_text("\n".join(lines) + "\n")
    elif kind == "single-branch":
        half = t.size // 4
        _write(path, ["temperature_C", "strain_percent"], [t[:half], e[:half]])
    elif kind == "constant-temperature":
        _write(path, ["temperature_C", "strain_percent"], [20.0 + 0.0 * t + np.sin(np.arange(t.size)), e])
    elif kind == "no-transformation":
        # cold only (2-20 degC): the strain creeps by 0.07 %, it never transforms
        _write(path, ["temperature_C", "strain_percent"],
               [0.15 * t, 1.0 + 0.07 * (t - t.min()) / np.ptp(t)])
    elif kind == "kelvin-as-celsius":
        _write(path, ["temperature_K", "strain_percent"], [t, e])
    elif kind == "fraction-as-percent":
        _write(path, ["temperature_C", "strain_percent"], [t, e / 100.0])
    elif kind == "percent-as-fraction":
        _write(path, ["temperature_C", "strain"], [t, e * 2.0 - 3.0])
    return path


@pytest.mark.parametrize("kind, parts", [
    ("one-column", ["only one column"]),
    ("text", ["line 41", "strain_percent = 'n/a' is not a number"]),
    ("single-branch", ["a single branch", "only goes one way"]),
    ("constant-temperature", ["does not vary"]),
    ("no-transformation", ["no transformation in range"]),
    ("kelvin-as-celsius", ["temperature_K", "look like degC", "mismatched units"]),
    ("fraction-as-percent", ["strain_percent", "look like a fraction", "mismatched units"]),
    ("percent-as-fraction", ["column strain", "look like percent", "mismatched units"]),
])
def test_bad_files_give_one_line_and_write_nothing(tmp_path, params, capsys, kind, parts):
    path = _bad(tmp_path, params, kind)
    out = tmp_path / "out"
    _fails(capsys, ["fit", "isobaric", str(path), "--load", "0.15", "--out", str(out)],
           str(path), *parts)
    assert not out.exists()


def test_load_must_be_given(tmp_path, params, capsys):
    c = _columns(params)
    path = _write(tmp_path / "c.csv", ["temperature_C", "strain_percent"],
                  [c["temperature_C"], c["strain_percent"]])
    _fails(capsys, ["fit", "isobaric", str(path), "--out", str(tmp_path / "o")], str(path),
           "no load given")
    _fails(capsys, ["fit", "isobaric", str(path), str(path), "--load", "0.1,0.2,0.3"],
           "--load has 3 values for 2 files")
    _fails(capsys, ["fit", "constant-load", str(path), "--load", "0.1"],
           "--load applies to isobaric only")


def test_lab_file_to_parameter_file_to_fmus_and_a_run(tmp_path, capsys):
    """The shipped example: fit, then build FMUs and run a scenario with the result."""
    example = shipped_file("examples", "isobaric.csv")
    out = tmp_path / "fit"
    assert main(["fit", "isobaric", str(example), "--out", str(out)]) == 0
    capsys.readouterr()
    report = json.loads((out / "report.json").read_text())
    fitted = load_parameter_set(out / "identified.toml")
    base = load_parameter_set()
    assert fitted.params.memory_depth == base.params.memory_depth
    centre = report["hysteresis_centres_degC"]["0.15 kg"]
    assert abs(centre["heating"]["value"] - (base.params.a_h + 0.15 * base.params.b_h)) \
        <= 4 * centre["heating"]["std_error"]
    assert report["covariance"]["parameters"] == list(report["parameters"])
    table = (out / "transformation_temperatures.csv").read_text().splitlines()
    assert table[0] == ("file,load_kg,cycle,quantity,unit,data,data_wire,model,data_note,"
                        "data_wire_note,model_note") and len(table) == 1 + 3 * 7
    assert (out / "transformation_temperatures.md").read_text().count("| A_s |") == 3
    assert report["verdict"].startswith("the model explains the data")
    for name in ("fit_isobaric_cycles.png", "fit_isobaric_residuals.png",
                 "fit_isobaric_stabilisation.png", "fit_isobaric_resistance.png"):
        assert (out / name).read_bytes()[:4] == b"\x89PNG"
    assert main(["build", "--model", str(out / "identified.toml"), "--out", str(tmp_path / "fmus")]) == 0
    scenario = tmp_path / "s.toml"
    scenario.write_text(shipped_file("scenarios", "heavy-pi.toml").read_text().replace(
        'stop_time_s = 30.0', f'stop_time_s = 3.0\nmodel = "{out / "identified.toml"}"'))
    assert main(["run", str(scenario), "--path", "library", "--out", str(tmp_path / "run")]) == 0


def test_synth_several_loads_writes_a_folder(tmp_path, capsys):
    out = tmp_path / "many"
    assert main(["synth", "isobaric", "--loads", "0.1,0.2", "--points", "800", "--out", str(out),
                 "--no-time", "--strain-unit", "fraction"]) == 0
    names = sorted(p.name for p in out.iterdir() if p.name != MARKER)   # MARKER: sma-fmu wrote it
    assert names == ["isobaric-0.1kg.csv", "isobaric-0.2kg.csv"] and (out / MARKER).is_file()
    data = read_isobaric(out / names[1])
    assert data.load == 0.2 and data.time is None and data.columns["strain"] == ("strain", "fraction")


def test_one_wild_residual_strain_is_marked_at_the_panel_s_edge_not_scaling_it():
    """The stabilisation figure's residual-strain panel: 99 cycles near zero and one at
    3.7 % keep their scale, and the wild one is named at the edge; a training drift of the
    first cycles (a few times the others) stays on the axis, unmarked."""
    from matplotlib.figure import Figure
    from sma_fmu.identification.isobaric.figures import _mark_beyond
    rng = np.random.default_rng(1)
    cycles = list(range(2, 101))
    data = list(rng.normal(0.003, 0.005, len(cycles)))
    model = list(rng.normal(0.003, 0.005, len(cycles)))
    data[14] = 3.69
    axis = Figure().subplots()
    axis.plot(cycles, data), axis.plot(cycles, model)
    _mark_beyond(axis, cycles, data + model)
    low, high = axis.get_ylim()
    assert high < 0.2 and low < min(model) and high > sorted(data)[-2]
    assert [t.get_text() for t in axis.texts] == ["cycle 16: 3.69 %"]
    drift = [0.07, 0.05] + data[2:14] + [0.004] + data[15:]
    axis = Figure().subplots()
    axis.plot(cycles, drift)
    _mark_beyond(axis, cycles, drift + model)
    assert not axis.texts and axis.get_ylim()[1] >= 0.07
