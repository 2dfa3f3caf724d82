"""A wire parameter outside its plausible range (tests/test_parameter_ranges.py) is refused by
the FMUs of both families, FMI 2.0 and 3.0, naming the parameter, its unit and the range:
set by the host in Initialization Mode, given in resources/start_values.json, or held in the
build's own resources (the C family's model_starts.json, the pythonfmu family's
parameters.json). The refusal is fmi2Error / fmi3Error at ExitInitializationMode (never
Fatal); the instance stays in Initialization Mode, where a good value is taken.

The fuzz campaign's finding: R_M, R_F, l_F of 1e30 ... DBL_MAX were accepted by all three
fronts and gave R up to 9e307 ohm or x = 5e29 m."""
import json
import math
import zipfile
from pathlib import Path

import pytest

from sma_fmu.runtime.parameters import PARAMETER_SPECS

from fmi3_twins import Instance3
from native_twins import LOGS, Instance

pytestmark = pytest.mark.needs("gcc")

DBL_MAX = 1.7976931348623157e308
# (model, parameter, value, words of the refusal after "= <value>")
CASES = [
    ("SmaActuator", "R_M", 1e30, "must be in (0, 100000] [ohm]"),
    ("SmaActuator", "R_F", DBL_MAX, "must be in (0, 100000] [ohm]"),
    ("SmaActuator", "l_F", 1e30, "must be in (0, 10] [m]"),
    ("SmaActuator", "x0", 800.0, "must be in (0, 10] [m]"),
    ("SmaActuator", "a_h", -1e30, "must be in [-273.15, 1000] [degC]"),
    ("SmaActuator", "stress_max", math.inf, "must be a finite number in (0, 2000] [MPa]"),
    ("SmaFeedforward", "R_M", 1e30, "must be in (0, 100000] [ohm]"),
    ("SmaFeedforward", "stress_max", math.inf, "must be a finite number in (0, 2000] [MPa]"),
    ("SmaFeedforward", "beta", 1e30, "must be in (0, 100000] [s]"),
    ("SmaPiController", "Kp", 1e30, "must be in [0, 1e+06] [W/ohm]"),
]
KINDS = ["python", "c-fmi2", "c-fmi3"]


def _paths(kind, fmus, native_fmus, fmi3_fmus):
    return {"python": fmus, "c-fmi2": native_fmus, "c-fmi3": fmi3_fmus}[kind]


def _open(kind, path, name):
    return (Instance3 if kind == "c-fmi3" else Instance)(path, name)


def _enter(fmu, kind):
    if kind == "c-fmi3":
        fmu.fmu.enterInitializationMode(startTime=0.0)
    else:
        fmu.fmu.setupExperiment(startTime=0.0)
        fmu.fmu.enterInitializationMode()


def _section(parameter):
    return next(f"{s.section}.{s.name}" for s in PARAMETER_SPECS if s.name == parameter)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("model,parameter,value,words", CASES)
def test_a_parameter_set_outside_its_range_is_refused_by_name(fmus, native_fmus, fmi3_fmus, kind,
                                                              model, parameter, value, words):
    path = _paths(kind, fmus, native_fmus, fmi3_fmus)[model]
    fmu = _open(kind, path, f"range-{kind}-{model}-{parameter}")
    try:
        _enter(fmu, kind)
        start = float(fmu.variables[parameter].start)
        assert fmu.set(parameter, value) == 0                   # stored; checked at exit
        assert fmu.call("exitInitializationMode")[0] == 3
        message = fmu.log[-1][1]
        assert f"parameter {_section(parameter)} = " in message and words in message, message
        assert fmu.set(parameter, start) == 0                   # corrected in place
        assert fmu.call("exitInitializationMode")[0] == 0
        assert fmu.step(0.0, 1e-3) == 0
    finally:
        fmu.close()


def _start_values(resources, values):
    (resources / "start_values.json").write_text(json.dumps({"values": values}))


def _repacked(path, prepare, folder):
    """A copy of the FMU at ``path`` in ``folder`` whose resources ``prepare(resources
    folder)`` changed (the FMU's own zip entries, rewritten)."""
    with zipfile.ZipFile(path) as source:
        source.extractall(folder / "unpacked")
    prepare(folder / "unpacked" / "resources")
    copy = folder / Path(path).name
    with zipfile.ZipFile(copy, "w", zipfile.ZIP_DEFLATED) as target:
        for file in sorted((folder / "unpacked").rglob("*")):
            if file.is_file():
                target.write(file, file.relative_to(folder / "unpacked").as_posix())
    return copy


@pytest.mark.parametrize("kind", KINDS)
def test_a_start_value_outside_its_range_in_resources_is_refused_by_name(
        fmus, native_fmus, fmi3_fmus, kind, tmp_path):
    path = _repacked(_paths(kind, fmus, native_fmus, fmi3_fmus)["SmaActuator"],
                     lambda resources: _start_values(resources, {"l_F": 1e30}), tmp_path)
    fmu = _open(kind, path, f"start-values-{kind}")
    try:
        _enter(fmu, kind)
        assert fmu.call("exitInitializationMode")[0] == 3
        assert "parameter phases.l_F = 1" in fmu.log[-1][1]
        assert "must be in (0, 10] [m]" in fmu.log[-1][1]
    finally:
        fmu.close()


@pytest.mark.parametrize("kind", ["c-fmi2", "c-fmi3"])
def test_a_build_default_outside_its_range_in_model_starts_is_refused_by_name(
        native_fmus, fmi3_fmus, kind, tmp_path):
    """The C family reads the parameters it does not expose from model_starts.json's
    wire_defaults: eps_f (constant_temperature) of 1e30 there is refused like a set one."""
    index = [spec.name for spec in PARAMETER_SPECS].index("eps_f")

    def prepare(resources):
        starts = resources / "model_starts.json"
        document = json.loads(starts.read_text())
        document["wire_defaults"][index] = 1e30
        starts.write_text(json.dumps(document))

    path = _repacked(_paths(kind, None, native_fmus, fmi3_fmus)["SmaActuator"], prepare, tmp_path)
    fmu = _open(kind, path, f"model-starts-{kind}")
    try:
        _enter(fmu, kind)
        assert fmu.call("exitInitializationMode")[0] == 3
        message = fmu.log[-1][1]
        assert "parameter constant_temperature.eps_f = 1" in message, message
        assert "must be in [-1e-17, 1e-17] [J]" in message
    finally:
        fmu.close()


def test_a_pythonfmu_build_whose_parameter_file_was_edited_is_refused_by_name(fmus, tmp_path):
    """The pythonfmu family reads its whole wire from resources/parameters.json when the
    instance is made: an edited value out of range makes fmi2Instantiate return NULL, and
    the log names the parameter, its unit and the range."""
    def prepare(resources):
        path = resources / "parameters.json"
        document = json.loads(path.read_text())
        document["parameters"]["R_F"]["value"] = 1e30
        path.write_text(json.dumps(document))

    name = "parameters-json-python"
    with pytest.raises(Exception, match="instantiate"):   # fmpy: "Failed to instantiate"
        Instance(_repacked(fmus["SmaActuator"], prepare, tmp_path), name)
    log = [text for status, text in LOGS[name] if status >= 2]
    assert any("parameter phases.R_F = 1e+30 must be in (0, 100000] [ohm]" in line
               for line in log), log
