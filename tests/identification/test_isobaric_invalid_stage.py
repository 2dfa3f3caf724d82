"""A richer structure that leaves the wire file's valid parameters is not kept, and the fit
goes on without it: three noise-free files at 200-400 MPa, cooled from 281 to -74 degC and
heated back (as simulated isobaric tests are written), sent the second stage's heating
centre at no load below absolute zero and stopped the whole fit with an error. Such a file
holds no cycle with both branches, so its thermal hysteresis is n/a: the report and the
console say why, and no note prints "nan"."""
import json

import numpy as np
import pytest

from sma_fmu.cli import main
from sma_fmu.identification.isobaric.layout import InvalidParameter
from sma_fmu.identification.measurements import MeasurementError

STRESSES = (200, 300, 400)          # [MPa]
TRANSFORMATION_STRAIN = 0.05        # [1]
WIDTH = 12.0                        # [K] of each logistic branch


def _centres(stress):
    """(heating, cooling) half-strain temperature [degC] at ``stress`` [MPa]: the truth."""
    return 15.7 + 0.164 * stress, -18.0 + 0.082 * stress


def _write(tmp_path, stress):
    """One cooling branch from 280.85 degC to -74.2 degC and one heating branch back, 300
    samples each, a logistic step of the transformation strain, no noise."""
    down = np.linspace(280.85, -74.2, 300)
    heating, cooling = _centres(stress)
    xi_cool = 1.0 / (1.0 + np.exp((down - cooling) / WIDTH))
    xi_heat = 1.0 / (1.0 + np.exp((down[::-1] - heating) / WIDTH))
    temperature = np.concatenate([down, down[::-1]])
    strain = stress / 68000.0 + TRANSFORMATION_STRAIN * np.concatenate([xi_cool, xi_heat])
    path = tmp_path / f"sim_{stress}MPa.txt"
    rows = "".join(f"{t:.6f} {e:.9f} {stress}\n" for t, e in zip(temperature, strain))
    path.write_text("Temperature Strain Stress\n" + rows, encoding="utf-8")
    return path


def test_an_invalid_parameter_is_a_measurement_error_naming_it():
    error = InvalidParameter("a.csv", "parameter second_stage.a2_h = -276.6 must be in "
                                      "[-273.15, 1000] [degC]")
    assert isinstance(error, MeasurementError)
    assert "a.csv: the fit reached an invalid parameter (parameter second_stage.a2_h" in str(error)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_a_second_stage_below_absolute_zero_leaves_the_one_stage_fit(tmp_path, capsys):
    paths = [_write(tmp_path, s) for s in STRESSES]
    out = tmp_path / "fit"
    assert main(["fit", "isobaric", *map(str, paths), "--quiet", "--out", str(out)]) == 0
    report = json.loads((out / "report.json").read_text(encoding="utf-8"))
    assert report["solver"]["converged"]
    assert (out / "identified.toml").is_file()
    for entry, stress in zip(report["half_strain"]["per_file"], STRESSES):
        heating, cooling = _centres(stress)
        assert entry["model_heating_degC"] == pytest.approx(heating, abs=1.0)
        assert entry["model_cooling_degC"] == pytest.approx(cooling, abs=1.0)
    console = capsys.readouterr().out
    for entry in report["hysteresis"]:
        assert entry["thermocouple_K"] is None and entry["wire_K"] is None
        assert "no such branch" in entry["thermocouple_K_why_missing"]
        assert "no such branch" in entry["wire_K_why_missing"]
        assert entry["narrowing_K_per_lag_unit"] is None and "nan" not in entry["note"]
        assert f"{entry['file']}: thermal hysteresis (median over cycles) n/a at the " \
               f"thermocouple, n/a at the wire (model) (n/a: heating, cooling: no such branch" in console
    lines = [line for line in console.splitlines() if "thermal hysteresis" in line]
    assert len(lines) == len(STRESSES)
    assert all(line.count("no such branch") == 1 for line in lines)   # each reason once
