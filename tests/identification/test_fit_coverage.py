"""What a fit's data covered and what it did not determine: the data range in identified.toml
and report.json (the Flexinol files: their own temperatures and stresses), the diameter of
every MPa <-> kg on the console and in the report, the parameters kept from the base file
("not identified here"), and ``fit constant-load`` completing an isobaric fit's file: its
transformation terms kept, the resistances fitted, the range narrowed to what both data
sets cover."""
import json

import numpy as np
import pytest

from real_isobaric import real_folder
from sma_fmu.cli import main
from sma_fmu.identification.synthetic import constant_load_rows, write_rows
from sma_fmu.wire.parameter_file import load_parameter_set, write_parameter_file

FLEXINOL = (50, 100, 172, 200)
# an isobaric fit's kind of file: a second stage, separate widths, the strain terms, a range
ISOBARIC_TERMS = dict(nu_h=150.0, nu_c=105.0, w2=0.3, a2_h=95.0, b2_h=80.0, a2_c=70.0,
                      b2_c=45.0, nu2_h=45.0, nu2_c=35.0, alpha_P=-4e-5, span_ratio_0=0.7,
                      span_stress=120.0, T_data_min=30.0, T_data_max=140.0,
                      stress_data_min=50.0, stress_data_max=200.0)
RESISTANCES = ("R_P", "R_M", "R_F", "xi_F_inf", "f_F")


@pytest.fixture(scope="module")
def flexinol(tmp_path_factory):
    files = [real_folder("flexinol-niti") / f"isobaric_{s}MPa.txt" for s in FLEXINOL]
    out = tmp_path_factory.mktemp("coverage") / "fit"
    return files, out


def test_the_flexinol_fit_records_its_range_diameter_and_what_it_kept(flexinol, capsys):
    files, out = flexinol
    assert main(["fit", "isobaric", *map(str, files), "--out", str(out)]) == 0
    console = capsys.readouterr().out
    fitted = load_parameter_set(out / "identified.toml").params
    report = json.loads((out / "report.json").read_text())
    # the files' own columns, read here with numpy: Temperature [degC], Stress [MPa]
    columns = [np.loadtxt(f, skiprows=1) for f in files]
    coldest = min(c[:, 0].min() for c in columns)
    hottest = max(c[:, 0].max() for c in columns)
    assert fitted.T_data_min <= coldest < fitted.T_data_min + 0.1
    assert fitted.T_data_max - 0.1 < hottest <= fitted.T_data_max
    assert 29.0 < coldest and hottest < 141.0          # what the issue measured: 30-140 degC
    assert fitted.stress_data_min == pytest.approx(50.0, abs=0.2)
    assert fitted.stress_data_max == pytest.approx(200.0, abs=0.2)
    assert (fitted.T_max, fitted.stress_max) == (300.0, 300.0)   # the physical limits stay
    coverage = report["coverage"]
    assert coverage["data_range"] == {"T_data_min": fitted.T_data_min,
                                      "T_data_max": fitted.T_data_max,
                                      "stress_data_min": fitted.stress_data_min,
                                      "stress_data_max": fitted.stress_data_max}
    assert coverage["stress_conversion"]["diameter_m"] == 0.15e-3
    assert "MPa <-> kg on a 0.15 mm wire" in console
    kept = coverage["not_identified_here"]["by_section"]
    assert kept["phases"] == {"R_P": 33.0, "R_M": 50.5, "R_F": 48.5}
    assert set(kept["thermal"]) == {"A_s", "c_p", "h_c", "T_room"}
    # the kept ambient (10 degC) is below the data (about 30 degC): every run at it warns
    ambient = kept["thermal"]["T_room"]
    assert ambient < fitted.T_data_min
    assert f"thermal.T_room = {ambient:g} degC is below the data's range" in coverage["ambient_note"]
    assert f"note: {coverage['ambient_note']}" in console
    assert "T_alpha" in kept["strain"] and "T_alpha" in coverage["not_identified_here"]["defaults"]
    assert not {"a_h", "w2", "nu_h", "alpha_P", "nu"} & {n for s in kept.values() for n in s}
    assert "not identified here" in console and "[phases] R_P, R_M, R_F" in console
    assert "Not identified here" in (out / "identified.toml").read_text()


@pytest.fixture()
def isobaric_base(tmp_path, parameter_set):
    wire = parameter_set.params.replace(**ISOBARIC_TERMS)
    path = write_parameter_file(tmp_path / "isobaric.toml", wire, "isobaric-like", "a test",
                                parameter_set.meanings)
    return path, wire


def test_constant_load_completes_an_isobaric_file(tmp_path, isobaric_base, capsys):
    path, base = isobaric_base
    truth = base.replace(R_P=31.0, R_M=52.0, R_F=49.0, xi_F_inf=0.15, f_F=0.25)
    rows = constant_load_rows(truth, [0.05, 0.15, 0.25], t_min=20.0, t_max=130.0)
    data = write_rows(tmp_path / "resistance.csv", rows)
    out = tmp_path / "completed"
    assert main(["fit", "constant-load", str(data), "--model", str(path), "--out", str(out)]) == 0
    console = capsys.readouterr().out
    completed = load_parameter_set(out / "identified.toml").params
    for name in RESISTANCES:       # noise-free data of the true wire: found again
        assert getattr(completed, name) == pytest.approx(getattr(truth, name), rel=1e-6), name
    for name in ("a_h", "b_h", "a_c", "b_c", "nu", *ISOBARIC_TERMS):
        if not name.startswith(("T_data", "stress_data")):
            assert getattr(completed, name) == getattr(base, name), name   # kept, exactly
    # the overlap of 30-140 degC / 50-200 MPa and these data (20-130 degC, 0.05-0.25 kg)
    stress_of = 9.80665 / (np.pi * 0.15e-3 ** 2 / 4) / 1e6    # MPa per kg
    assert (completed.T_data_min, completed.T_data_max) == (30.0, 130.0)
    assert completed.stress_data_min == 50.0
    assert completed.stress_data_max == pytest.approx(0.25 * stress_of, abs=0.1)
    report = json.loads((out / "report.json").read_text())
    assert report["kept_from_base"]["parameters"] == ["a_h", "b_h", "a_c", "b_c", "nu"]
    assert list(report["parameters"]) == list(RESISTANCES)
    assert "kept from the base file: a_h, b_h, a_c, b_c, nu" in console


def test_constant_load_on_the_reference_fits_as_before_and_gets_a_range(tmp_path, params):
    truth = params.replace(a_h=72.0, R_P=32.0)
    rows = constant_load_rows(truth, [0.0032, 0.05, 0.15, 0.25], t_min=0.0, t_max=150.0)
    data = write_rows(tmp_path / "resistance.csv", rows)
    out = tmp_path / "fit"
    assert main(["fit", "constant-load", str(data), "--out", str(out)]) == 0
    fitted = load_parameter_set(out / "identified.toml").params
    report = json.loads((out / "report.json").read_text())
    assert report["kept_from_base"] is None and "a_h" in report["parameters"]
    assert fitted.a_h == pytest.approx(72.0, rel=1e-6)
    assert (fitted.T_data_min, fitted.T_data_max) == (0.0, 150.0)
    stress_of = 9.80665 / (np.pi * 0.15e-3 ** 2 / 4) / 1e6    # MPa per kg
    assert fitted.stress_data_min <= 0.0032 * stress_of < fitted.stress_data_min + 0.1
    assert "nu_h" not in report["coverage"]["not_identified_here"]["by_section"]["constant_load"]
    assert report["coverage"]["not_identified_here"]["by_section"]["thermal"]["h_c"] == 106.0


def test_a_cooling_transformation_incomplete_at_the_ambient_is_noted():
    """A wire whose cooling centre at the data's lowest load sits at its T_room (a NiTi with
    M_f below the bench's ambient) is half transformed there, closed form of the logistic
    at its centre: the note says 50 %; the reference wire's 10 degC room, 42 K below that
    centre, gives none."""
    from sma_fmu.files.package_data import shipped_file
    from sma_fmu.identification.coverage import coverage
    base = load_parameter_set(shipped_file("models", "reference_wire.toml"))
    ranged = base.params.replace(T_data_min=0.0, T_data_max=120.0, stress_data_min=50.0,
                                 stress_data_max=100.0)
    assert base.params.w2 is None and (base.params.a_c, base.params.b_c) == (52.0, 60.0)
    assert coverage(ranged, base, set(), "")["ambient_note"] == ""
    centre = 52.0 + 60.0 * ranged.load_data_min           # a_c + b_c f, spec section 4
    warm = ranged.replace(T_room=centre)
    note = coverage(warm, base, set(), "")["ambient_note"]
    assert note.startswith("at 50 MPa the model's cooling transformation is only 50 % complete "
                           f"at thermal.T_room = {centre:g} degC")
