"""Parameter files: the reference file loads, round-trips, and malformed files are rejected."""
from dataclasses import fields

import pytest

from sma_fmu.wire.parameter_file import load_parameter_set, write_parameter_file
from sma_fmu.files.package_data import default_parameter_file
from sma_fmu.runtime.parameters import PARAMETER_SPECS, ParameterError, WireParameters


def test_schema_matches_dataclass_fields():
    names = [f.name for f in fields(WireParameters) if f.init and f.name != "source"]
    assert sorted(names) == sorted(spec.name for spec in PARAMETER_SPECS)


def test_reference_file_has_unit_and_meaning_for_every_entry(parameter_set):
    assert parameter_set.name == "reference"
    for spec in PARAMETER_SPECS:
        if spec.required:
            assert parameter_set.meanings[spec.name], spec.name
    assert parameter_set.params.alpha is None
    assert parameter_set.params.phase_lag_alpha == parameter_set.params.tau_th


def test_written_file_reloads_exactly(tmp_path, parameter_set):
    changed = parameter_set.params.replace(a_h=71.25, R_P=32.123456789012345, alpha=0.9)
    path = write_parameter_file(tmp_path / "wire.toml", changed, "changed", "a test wire",
                                parameter_set.meanings, header=["written by a test"])
    again = load_parameter_set(path)
    assert again.params == changed
    assert again.name == "changed" and again.meanings["a_h"] == parameter_set.meanings["a_h"]


def _write_variant(tmp_path, old, new):
    text = default_parameter_file().read_text(encoding="utf-8")
    assert old in text, old
    path = tmp_path / "variant.toml"
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return path


@pytest.mark.parametrize("old,new,match", [
    ('unit = "ohm", meaning = "wire resistance if all P phase"',
     'unit = "kohm", meaning = "wire resistance if all P phase"',
     r"parameter phases.R_P has unit 'kohm'; expected 'ohm'"),
    ("R_P = { value = 33.0,", "R_P = { value = \"33\",",
     r"parameter phases.R_P value must be a number \[ohm\], got '33'"),
    ("R_P = { value = 33.0,", "R_P = { value = nan,",
     r"parameter geometry.R_P|parameter phases.R_P = nan must be a finite number in "
     r"\(0, 100000\] \[ohm\]"),
    ("R_P = { value = 33.0,", "R_P = { value = -33.0,",
     r"parameter phases.R_P = -33.0 must be in \(0, 100000\] \[ohm\]"),
    ("R_P = { value = 33.0,", "R_X = { value = 33.0,",
     r"unknown parameter phases.R_X"),
    ("[sensing]", "[sensors]", r"unknown section\(s\) sensors"),
    ("theta    = { value = 0.5,", "theta    = { value = 1.5,",
     r"parameter geometry.theta = 1.5 must be in \[0, 1\) \[1\]"),
    ("R_P = { value = 33.0,", "R_P = { value = 55.0,",
     r"\(R_M \+ R_F\)/2 = 49.5 ohm must exceed R_P = 55.0 ohm"),
    ("R_P = { value = 33.0,", "R_P = { valu = 33.0,", r"parameter phases.R_P has unknown field"),
    ("x0       = { value = 0.800,", "x0       = { value = 0.800,,", r"not valid TOML"),
])
def test_malformed_file_is_rejected_naming_file_key_and_value(tmp_path, old, new, match):
    path = _write_variant(tmp_path, old, new)
    with pytest.raises(ParameterError, match=match) as raised:
        load_parameter_set(path)
    assert str(path) in str(raised.value)


def test_missing_key_is_named(tmp_path):
    text = default_parameter_file().read_text(encoding="utf-8")
    lines = [line for line in text.splitlines() if not line.startswith("nu_f")]
    path = tmp_path / "missing.toml"
    path.write_text("\n".join(lines), encoding="utf-8")
    with pytest.raises(ParameterError, match=r"missing parameter\(s\) constant_temperature.nu_f"):
        load_parameter_set(path)


def test_missing_file_is_named(tmp_path):
    with pytest.raises(ParameterError, match=r"nowhere.toml: parameter file not found"):
        load_parameter_set(tmp_path / "nowhere.toml")


def test_replace_rejects_unknown_names(params):
    with pytest.raises(ParameterError, match=r"unknown parameter\(s\) R_Q"):
        params.replace(R_Q=1.0)
