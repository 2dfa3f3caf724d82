"""Parameter identification: recovery from synthetic data, reports, and bad files."""
import json

import numpy as np
import pytest

from sma_fmu.cli import main
from sma_fmu.identification.constant_load import FITTED, fit_constant_load, starting_parameters
from sma_fmu.identification.constant_temperature import fit_constant_temperature
from sma_fmu.identification.measurements import MeasurementError, read_constant_load, read_constant_temperature
from sma_fmu.wire.parameter_file import load_parameter_set, write_parameter_file
from sma_fmu.identification.synthetic import constant_load_rows, constant_temperature_rows, write_rows

LOADS = [3.2e-3, 0.05, 0.15, 0.25]
CYCLE = [0.0, 0.1, 0.03, 0.2, 0.03, 0.3]


# parameters that move in one direction together, so the perturbed wire stays physical
# ((R_M + R_F)/2 > R_P) and keeps its hysteresis orientation (heating centre above cooling)
_TOGETHER = ({"R_P", "R_M", "R_F"}, {"a_h", "a_c"})


def _perturbed(params, names, seed):
    """Parameters moved 10-30 % from the defaults (random size and sign, seeded)."""
    rng = np.random.default_rng(seed)
    signs = {n: rng.choice([-1, 1]) for n in names}
    for group in _TOGETHER:
        shared = rng.choice([-1, 1])
        signs.update({n: shared for n in group if n in signs})
    return params.replace(**{n: getattr(params, n) * (1 + signs[n] * rng.uniform(0.1, 0.3))
                             for n in names})


def _constant_load(tmp_path, truth, noise_ohm, noise_K, seed=11, name="cl.csv", **kwargs):
    """Sweeps 0-150 degC: wide enough for transformation temperatures moved by up to 30 %."""
    rows = constant_load_rows(truth, LOADS, t_min=0.0, t_max=150.0, noise_ohm=noise_ohm,
                              noise_K=noise_K, seed=seed, **kwargs)
    path = write_rows(tmp_path / name, rows)
    return read_constant_load([path])


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_noisy_constant_load_recovery(tmp_path, params, seed):
    truth = _perturbed(params, FITTED, seed)
    result, report = fit_constant_load(_constant_load(tmp_path, truth, 0.05, 0.3, seed=seed), params)
    fitted = result.params
    for load in LOADS:
        assert abs((fitted.a_h + fitted.b_h * load) - (truth.a_h + truth.b_h * load)) < 0.5
        assert abs((fitted.a_c + fitted.b_c * load) - (truth.a_c + truth.b_c * load)) < 0.5
    for name in ("R_P", "R_M", "R_F"):
        assert getattr(fitted, name) == pytest.approx(getattr(truth, name), rel=5e-3)
    assert report["mape_percent"] < 1.0
    assert result.converged


def test_noise_free_constant_load_recovery(tmp_path, params):
    truth = _perturbed(params, FITTED, 7)
    result, report = fit_constant_load(_constant_load(tmp_path, truth, 0.0, 0.0), params)
    for name in FITTED:
        assert getattr(result.params, name) == pytest.approx(getattr(truth, name), rel=1e-6), name
    assert report["temperature_sensing"]["core_5_95_percent"]["max_abs_K"] < 1e-6


def test_noise_free_constant_temperature_recovery(tmp_path, params):
    truth = _perturbed(params, ("eps_f", "nu_f"), 5)
    path = write_rows(tmp_path / "ct.csv", constant_temperature_rows(truth, 20.0, CYCLE))
    result, report = fit_constant_temperature([read_constant_temperature(path)], params)
    assert result.params.eps_f == pytest.approx(truth.eps_f, rel=1e-6)
    assert result.params.nu_f == pytest.approx(truth.nu_f, rel=1e-6)
    assert report["critical_load_kg"] == pytest.approx(
        truth.eps_f * truth.N / (9.80665 * truth.x_f), rel=1e-6)


def test_noisy_constant_temperature_recovery(tmp_path, params):
    truth = _perturbed(params, ("eps_f", "nu_f"), 6)
    path = write_rows(tmp_path / "ct.csv", constant_temperature_rows(
        truth, 20.0, CYCLE, noise_ohm=0.05, noise_K=0.3, seed=4))
    result, report = fit_constant_temperature([read_constant_temperature(path)], params)
    critical = lambda p: p.eps_f * p.N / (9.80665 * p.x_f)
    assert critical(result.params) == pytest.approx(critical(truth), rel=0.02)
    assert report["mape_percent"] < 1.0


def test_starting_values_come_from_the_data_not_the_defaults(tmp_path, params):
    truth = _perturbed(params, FITTED, 9)
    starts = {p.name: p.start for p in starting_parameters(_constant_load(tmp_path, truth, 0.05, 0.3),
                                                           params)}
    for name in ("a_h", "a_c", "R_P"):
        assert abs(starts[name] - getattr(truth, name)) < abs(getattr(params, name) - getattr(truth, name))
    assert starts["nu"] == pytest.approx(truth.nu, rel=0.1)


def test_direction_inferred_from_the_temperature_sequence(tmp_path, params):
    truth = _perturbed(params, FITTED, 4)
    given = _constant_load(tmp_path, truth, 0.0, 0.0, name="given.csv")
    inferred = _constant_load(tmp_path, truth, 0.0, 0.0, name="inferred.csv", with_direction=False)
    assert np.array_equal(given.direction, inferred.direction)


def test_synth_is_seeded_and_reproducible(tmp_path):
    argv = ["synth", "constant-load", "--noise-ohm", "0.05", "--noise-K", "0.3"]
    for name, seed in (("a.csv", "1"), ("b.csv", "1"), ("c.csv", "2")):
        assert main(argv + ["--seed", seed, "--out", str(tmp_path / name)]) == 0
    a, b, c = ((tmp_path / n).read_text() for n in ("a.csv", "b.csv", "c.csv"))
    assert a == b and a != c
    assert a.splitlines()[0] == "temperature_C,load_kg,resistance_ohm,direction"


def test_cli_fit_writes_a_usable_parameter_file_and_report(tmp_path, parameter_set, capsys):
    truth = _perturbed(parameter_set.params, FITTED, 3)
    model = write_parameter_file(tmp_path / "truth.toml", truth, "truth", "", parameter_set.meanings)
    data = tmp_path / "sweeps.csv"
    assert main(["synth", "constant-load", "--model", str(model), "--noise-ohm", "0.05",
                 "--noise-K", "0.3", "--seed", "5", "--t-min", "0", "--t-max", "150",
                 "--out", str(data)]) == 0
    out = tmp_path / "fit"
    assert main(["fit", "constant-load", str(data), "--out", str(out)]) == 0
    assert "MAPE" in capsys.readouterr().out
    identified = load_parameter_set(out / "identified.toml")
    assert identified.params.a_h == pytest.approx(truth.a_h, abs=0.5)
    assert identified.meanings["a_h"] == parameter_set.meanings["a_h"]
    report = json.loads((out / "report.json").read_text())
    row = report["parameters"]["a_h"]
    assert row["ci95"][0] < row["value"] < row["ci95"][1] and row["std_error"] > 0
    assert len(report["per_load_and_direction"]) == 8
    assert report["temperature_sensing"]["core_5_95_percent"]["rmse_K"] < 1.0
    for figure in ("fit_resistance_temperature.png", "fit_temperature_sensing.png", "fit_residuals.png"):
        assert (out / figure).stat().st_size > 10000
    # the identified file feeds the constant-temperature fit and the FMU build unchanged
    cycle = tmp_path / "cycle.csv"
    assert main(["synth", "constant-temperature", "--model", str(out / "identified.toml"),
                 "--out", str(cycle)]) == 0
    assert main(["fit", "constant-temperature", str(cycle), "--model", str(out / "identified.toml"),
                 "--out", str(tmp_path / "fit2")]) == 0
    from sma_fmu.fmi.packaging.build import build_fmu
    from fmpy import read_model_description
    fmu = build_fmu("SmaActuator", tmp_path / "fmus", out / "identified.toml")
    starts = {v.name: v.start for v in read_model_description(str(fmu)).modelVariables}
    assert float(starts["a_h"]) == identified.params.a_h


GOOD = "temperature_C,load_kg,resistance_ohm,direction\n"


@pytest.mark.parametrize("text,message", [
    ("temperature_C,load_kg,direction\n20,0.05,heating\n",
     r"line 1: missing column\(s\) resistance_ohm; found temperature_C, load_kg, direction"),
    (GOOD + "20,0.05,49.4,heating\n21,0.05,abc,heating\n", r"line 3: resistance_ohm = 'abc' is not a number"),
    (GOOD + "20,0.05,49.4,heating\nnan,0.05,49.4,heating\n", r"line 3: temperature_C = 'nan' is not finite"),
    (GOOD + "20,0.05,49.4,heating\n21,-0.05,49.4,heating\n", r"line 3: load_kg = -0.05 must be >= 0"),
    (GOOD + "20,0.05,49.4,up\n", r"line 2: direction = 'up'; expected heating or cooling"),
    (GOOD + "20,0.05,,heating\n", r"line 2: column resistance_ohm is empty"),
    (GOOD + "20,0.05,49.4,heating\n20,0.1,49.4,cooling\n", r"only one temperature \(20.0 degC\)"),
    ("", r"line 1: the file is empty"),
    (GOOD, r"no data rows after the header"),
])
def test_bad_constant_load_file(tmp_path, text, message):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(MeasurementError, match=message) as raised:
        read_constant_load([path])
    assert str(path) in str(raised.value)


def test_no_transformation_in_range(tmp_path, params):
    rows = constant_load_rows(params, LOADS, t_min=10.0, t_max=40.0, noise_ohm=0.01, seed=1)
    data = read_constant_load([write_rows(tmp_path / "cold.csv", rows)])
    with pytest.raises(MeasurementError, match=r"cold.csv: no transformation in range at load "
                                               r"0.0032 kg \(.*\): resistance spans only"):
        fit_constant_load(data, params)


@pytest.mark.parametrize("loads,keep,message", [
    ([0.05, 0.15], None, r"2 load\(s\) \(0.05, 0.15 kg\); identifying the load dependence needs at least 3"),
    (LOADS, "heating", r"only heating sweeps; heating and cooling sweeps are both needed"),
])
def test_data_that_cannot_identify_the_model(tmp_path, params, loads, keep, message):
    rows = constant_load_rows(params, loads)
    if keep:
        rows = [row for row in rows if row["direction"] == keep]
    with pytest.raises(MeasurementError, match=message):
        fit_constant_load(read_constant_load([write_rows(tmp_path / "few.csv", rows)]), params)


def test_bad_constant_temperature_files(tmp_path, params):
    spread = tmp_path / "spread.csv"
    spread.write_text("load_kg,resistance_ohm,temperature_C\n0,49.4,20\n0.1,49.2,20.5\n0.2,49.0,26\n")
    with pytest.raises(MeasurementError, match=r"spread.csv: line 4: temperature_C spreads over 6 K"):
        read_constant_temperature(spread)
    light = write_rows(tmp_path / "light.csv", constant_temperature_rows(params, 20.0, [0.0, 0.05, 0.0]))
    with pytest.raises(MeasurementError, match=r"light.csv: no transformation in range: the resistance "
                                               r"changes by only"):
        fit_constant_temperature([read_constant_temperature(light)], params)


def test_failed_fit_writes_nothing(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text(GOOD + "20,0.05,49.4,heating\n21,0.05,oops,heating\n")
    out = tmp_path / "out"
    assert main(["fit", "constant-load", str(bad), "--out", str(out)]) == 2
    assert "line 3: resistance_ohm = 'oops' is not a number" in capsys.readouterr().err
    assert not out.exists()
    assert main(["fit", "constant-load", str(tmp_path / "missing.csv"), "--out", str(out)]) == 2
    assert "missing.csv: file not found" in capsys.readouterr().err
    assert not out.exists()
