"""Wires defined by their geometry: A_s and the mass derived, explicit values win, contradictions fail."""
import json
import math

import pytest

from sma_fmu.cli import main
from sma_fmu.wire.parameter_file import load_parameter_set
from sma_fmu.files.package_data import shipped_file
from sma_fmu.runtime.parameters import ParameterError

NITI_DENSITY = 6450.0  # kg/m3


def _wire_file(tmp_path, drop=(), add=()):
    """The reference wire file with the entries ``drop`` removed and lines ``add`` appended to
    [geometry]."""
    lines = [line for line in shipped_file("models", "reference_wire.toml").read_text().splitlines()
             if line.split("=")[0].strip() not in drop]
    at = lines.index("[geometry]") + 1
    lines[at:at] = list(add)
    path = tmp_path / "wire.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_reference_wire_derives_nothing(parameter_set):
    assert parameter_set.derived == {}


def test_area_and_mass_from_diameter_length_and_density(tmp_path, params):
    path = _wire_file(tmp_path, drop=("A_s", "mass"),
                      add=[f'density = {{ value = {NITI_DENSITY}, unit = "kg/m3" }}'])
    loaded = load_parameter_set(path)
    d, x0 = params.diameter, params.x0
    assert loaded.params.A_s == pytest.approx(math.pi * d * x0, rel=1e-15)
    assert loaded.params.mass == pytest.approx(NITI_DENSITY * math.pi * d * d / 4 * x0, rel=1e-15)
    assert set(loaded.derived) == {"A_s", "mass"} and "geometry.density" in loaded.derived["mass"]
    # the paper's A_s is the lateral surface of the reference wire
    assert loaded.params.A_s == pytest.approx(params.A_s, rel=2e-3)
    # the thermal constants follow: tau_th = m c_p / (h_c A_s)
    assert loaded.params.tau_th == pytest.approx(
        loaded.params.mass * params.c_p / (params.h_c * loaded.params.A_s), rel=1e-14)


def test_mass_from_linear_density(tmp_path, params):
    path = _wire_file(tmp_path, drop=("mass",),
                      add=['linear_density = { value = 1.12e-4, unit = "kg/m" }'])
    loaded = load_parameter_set(path)
    assert loaded.params.mass == pytest.approx(1.12e-4 * params.x0, rel=1e-15)
    assert loaded.params.A_s == params.A_s and set(loaded.derived) == {"mass"}


def test_explicit_values_win_when_consistent(tmp_path, params):
    consistent = params.mass / (math.pi * params.diameter ** 2 / 4 * params.x0)
    path = _wire_file(tmp_path, add=[f'density = {{ value = {consistent!r}, unit = "kg/m3" }}'])
    loaded = load_parameter_set(path)
    assert loaded.params.mass == params.mass and loaded.derived == {}


def test_a_contradiction_names_both_keys(tmp_path):
    path = _wire_file(tmp_path, add=[f'density = {{ value = {2 * NITI_DENSITY}, unit = "kg/m3" }}'])
    with pytest.raises(ParameterError, match=r"geometry.mass = 8.96e-05 and geometry.density = "
                                             r"12900.0 contradict each other"):
        load_parameter_set(path)


def test_no_way_to_the_mass(tmp_path):
    with pytest.raises(ParameterError, match="missing parameter geometry.mass: give mass"):
        load_parameter_set(_wire_file(tmp_path, drop=("mass",)))


def test_wire_command_says_what_was_derived(tmp_path, capsys):
    path = _wire_file(tmp_path, drop=("A_s", "mass"),
                      add=[f'density = {{ value = {NITI_DENSITY}, unit = "kg/m3" }}'])
    assert main(["wire", "--model", str(path), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["derived A_s"].startswith("pi * diameter * x0")
    assert summary["thermal.A_s"] == pytest.approx(summary["surface pi d x0"])
    assert "T_room = 10 degC" in summary["note"]
    assert main(["lattice", "--model", str(path)]) == 0
    assert "derived mass = density" in capsys.readouterr().out
