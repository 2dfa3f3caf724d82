"""One folder per FMU (sma_fmu/fmi/models/<Model>/) and one registry line: the declarations the
builds read agree with the folders, the C adapters, the slaves and the loop's wiring, and a
broken declaration is refused naming its file and key."""
import importlib
import re

import pytest

from sma_fmu.fmi.models import REGISTRY, declaration, declarations
from sma_fmu.fmi.models.declaration import FOLDER, read_declaration
from sma_fmu.fmi.packaging.c_family_build import c_source_files, model_sources
from sma_fmu.fmi.loop.wiring import COMPONENT_MODELS


def test_every_folder_is_registered_and_every_registered_fmu_has_its_folder():
    folders = sorted(path.name for path in FOLDER.iterdir()
                     if path.is_dir() and path.name != "__pycache__")
    assert folders == sorted(REGISTRY) and "SmaActuator" in REGISTRY
    assert [declared.name for declared in declarations()] == list(REGISTRY)


def test_an_unknown_fmu_is_refused_naming_the_registered_ones():
    with pytest.raises(ValueError, match=r"unknown FMU 'SmaNothing'; expected one of SmaActuator, "):
        declaration("SmaNothing")
    with pytest.raises(ValueError, match=r"unknown FMU 'SmaActuater' \(did you mean 'SmaActuator'\?\); "):
        declaration("SmaActuater")


@pytest.mark.parametrize("name", REGISTRY)
def test_the_slave_defines_the_one_class_named_after_its_fmu(name):
    declared = declaration(name)
    classes = re.findall(r"^class (\w+)\(", declared.slave_path.read_text(encoding="utf-8"), flags=re.M)
    assert classes == [name]
    assert getattr(importlib.import_module(declared.slave_module), name).__name__ == name


def test_events_are_declared_where_the_c_adapter_has_next_event():
    has_next_event = {declared.name: "static double next_event(" in
                      declared.c_model.read_text(encoding="utf-8") for declared in declarations()}
    assert has_next_event["SmaPwmDriver"] and not has_next_event["SmaActuator"]   # the check reads
    assert {declared.name: declared.events for declared in declarations()} == has_next_event


def test_the_loop_components_are_those_the_loop_wiring_connects():
    assert {declared.loop: declared.name for declared in declarations() if declared.loop} \
        == COMPONENT_MODELS


def test_the_c_family_compiles_each_adapter_from_its_folder():
    files = c_source_files()
    for declared in declarations():
        assert files[declared.c_model.name] == declared.c_model
        generated = (f"{declared.name}_variables.h",)
        assert declared.c_model.name in model_sources(declared.name, generated=generated)


def _folder(tmp_path, text, files=("sma_new.py", "SmaNew.c", "page.html")):
    folder = tmp_path / "SmaNew"
    folder.mkdir()
    (folder / "fmu.toml").write_text(text, encoding="utf-8")
    for name in files:
        (folder / name).write_text("", encoding="utf-8")
    return tmp_path


def test_a_minimal_declaration_reads_with_its_defaults(tmp_path):
    declared = read_declaration("SmaNew", _folder(tmp_path, 'slave = "sma_new.py"\n'))
    assert (declared.slave, declared.loop, declared.events, declared.stimuli, declared.default_signals) \
        == ("sma_new.py", None, False, {}, None)


@pytest.mark.parametrize("text, files, message", [
    ('slave = "sma_new.py"\ncolour = "red"\n', None, r"unknown key 'colour'"),
    ('slave = "sma_new.py"\nevents = "yes"\n', None, r"events must be a bool, got 'yes'"),
    ('loop = "plant"\n', None, r"no slave"),
    ('slave = "sma_new.py"\n', ("sma_new.py", "page.html"), r"its C adapter SmaNew\.c is not in"),
    ('slave = "other.py"\n', None, r"its slave other\.py is not in"),
    ('slave = "sma_new.py"\n[stimuli]\nP_in = [[0.0, 1.0], [2.0]]\n', None,
     r"stimuli\.P_in must be rows \[t s, value\] of finite numbers"),
    ('slave = "sma_new.py"\n[stimuli]\nP_in = [[1.0, 1.0], [0.5, 2.0]]\n', None,
     r"stimuli\.P_in: the times must rise"),
    ('slave = "sma_new.py"\n[stimuli]\nP_in = [[0.0, nan]]\n', None, r"stimuli\.P_in must be rows"),
    ('slave = \n', None, r"not valid TOML"),
])
def test_a_broken_declaration_is_refused_naming_its_file_and_key(tmp_path, text, files, message):
    folder = _folder(tmp_path, text, files or ("sma_new.py", "SmaNew.c", "page.html"))
    with pytest.raises(ValueError, match=message) as caught:
        read_declaration("SmaNew", folder)
    assert str(folder / "SmaNew" / "fmu.toml") in str(caught.value)
