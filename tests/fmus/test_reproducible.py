"""Reproducible builds (sma_fmu/fmi/packaging/reproducible.py): two builds of the same inputs
give byte-identical FMU files, in both families; the C family's binary holds the model's
structure's GUID (start values do not count) and its model description the token of that
structure and the wire's digest, the Python family's GUID is its content's."""
import json
import tempfile
import zipfile

import pytest

from sma_fmu import __version__
from sma_fmu.fmi.packaging.reproducible import fixed_date_time, structural_guid, wire_token

DESCRIPTION = b"""<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="M" guid="{x}" generationDateAndTime="2026-01-01">
  <CoSimulation modelIdentifier="M"/>
  <ModelVariables>
    <ScalarVariable name="k" valueReference="0" causality="parameter" variability="fixed">
      <Real start="1.5"/></ScalarVariable>
    <ScalarVariable name="y" valueReference="1" causality="output" variability="continuous">
      <Real/></ScalarVariable>
  </ModelVariables>
</fmiModelDescription>"""


def test_the_structural_guid_ignores_starts_and_dates_but_not_the_interface():
    guid = structural_guid(DESCRIPTION, "1.0")
    assert guid.startswith("{") and len(guid) == 38
    assert structural_guid(DESCRIPTION.replace(b'start="1.5"', b'start="2.5"')
                           .replace(b"2026-01-01", b"2027-02-02"), "1.0") == guid
    for changed in (DESCRIPTION.replace(b'"output"', b'"local"'),
                    DESCRIPTION.replace(b'name="y"', b'name="z"'),
                    DESCRIPTION.replace(b"<Real/>", b"<Integer/>"),
                    DESCRIPTION.replace(b'valueReference="1"', b'valueReference="2"')):
        assert structural_guid(changed, "1.0") != guid
    assert structural_guid(DESCRIPTION, "1.1") != guid


def test_source_date_epoch_sets_the_timestamps(monkeypatch):
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    assert fixed_date_time() == (1980, 1, 1, 0, 0, 0)
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    assert fixed_date_time() == (2023, 11, 14, 22, 13, 20)


def _entries(path):
    with zipfile.ZipFile(path) as archive:
        return [(i.filename, i.date_time, i.external_attr) for i in archive.infolist()]


@pytest.mark.needs("gcc", "mingw-w64")
@pytest.mark.parametrize("native", [False, True], ids=["python-family", "c-family"])
def test_two_builds_give_the_same_bytes(fmus, native_fmus, tmp_path, native, monkeypatch):
    from sma_fmu.fmi.packaging.build import build_fmus
    first = native_fmus if native else fmus
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))  # an empty compiler cache: compiled again
    again = build_fmus(tmp_path / "again", native=native)
    for name, path in first.items():
        assert again[name].read_bytes() == path.read_bytes(), name
        assert {date for _, date, _ in _entries(path)} == {fixed_date_time()}
        with zipfile.ZipFile(path) as archive:
            description = archive.read("modelDescription.xml")
        assert b"generationDateAndTime" not in description
        if native:
            with zipfile.ZipFile(path) as archive:
                digest = json.loads(archive.read("resources/parameters.json"))["wire_digest"]
            token = wire_token(structural_guid(description, __version__), digest)
            assert f'guid="{token}"'.encode() in description


@pytest.mark.needs("gcc")
def test_another_parameter_file_gives_the_same_c_family_binaries(native_fmus, tmp_path):
    """The binaries hold no parameter file's values: those travel in resources/."""
    from sma_fmu.fmi.packaging.c_family_build import build_native_fmus
    from sma_fmu.files.package_data import shipped_file
    text = shipped_file("models", "reference_wire.toml").read_text(encoding="utf-8")
    other = tmp_path / "other.toml"
    other.write_text(text.replace("R_P = { value = 33.0,", "R_P = { value = 34.5,"), encoding="utf-8")
    assert other.read_text(encoding="utf-8") != text
    built = build_native_fmus(tmp_path / "other", other, names=["SmaActuator"])["SmaActuator"]
    with zipfile.ZipFile(native_fmus["SmaActuator"]) as first, zipfile.ZipFile(built) as second:
        binaries = [n for n in first.namelist() if n.startswith("binaries/")]
        assert len(binaries) >= 2 and binaries == [n for n in second.namelist() if n.startswith("binaries/")]
        for name in binaries:
            assert first.read(name) == second.read(name), name
        assert first.read("resources/model_starts.json") != second.read("resources/model_starts.json")
        assert b'"R_P"' in first.read("resources/parameters.json")
    # the model description's GUID names the wire: another parameter file, another GUID
    from fmpy import read_model_description
    assert read_model_description(str(built)).guid != read_model_description(str(native_fmus["SmaActuator"])).guid
