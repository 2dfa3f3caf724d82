"""The built FMUs: fmpy validation, declared interface, shipped code, CLI build/validate."""
import math
import zipfile

import pytest
from fmpy import read_model_description

from import_roots import imported_roots
from sma_fmu.cli import main
from sma_fmu.fmi.packaging.fmu_names import FMU_SCRIPTS
from sma_fmu.fmi.packaging.build import build_fmu, validate_fmus
from sma_fmu.fmi.packaging.pythonfmu_build import code_stamp
from sma_fmu.wire.parameter_file import write_parameter_file
from sma_fmu.runtime.reachable_band import reachable_band
from sma_fmu.fmi.python_family.slave_support.model_description import UNIT_DEFINITIONS

PLANT_OUTPUTS = {"R": "ohm", "T": "degC", "x": "m", "xi_P": "1", "xi_M": "1", "xi_F": "1", "P": "W"}
FEEDFORWARD_OUTPUTS = {"P_ff": "W", "T_ref": "degC"}


def test_both_fmus_validate_with_no_problems(fmus):
    results = validate_fmus(fmus.values())
    assert results == {path: [] for path in fmus.values()}


@pytest.mark.parametrize("name", ["SmaActuator", "SmaFeedforward"])
def test_every_variable_has_description_and_every_real_a_defined_unit(fmus, name):
    description = read_model_description(str(fmus[name]))
    units = {unit.name for unit in description.unitDefinitions}
    assert units <= set(UNIT_DEFINITIONS)
    for variable in description.modelVariables:
        assert variable.description, variable.name
        if variable.type == "Real":
            assert variable.unit in units, variable.name
    experiment = description.defaultExperiment
    assert (experiment.startTime, experiment.stopTime, experiment.stepSize) == ("0.0", "10.0", "0.001")
    outputs = {v for v in description.modelVariables if v.causality == "output"}
    assert {u.variable for u in description.initialUnknowns} == outputs
    assert all(u.dependencies == [] for u in description.outputs)


@pytest.mark.parametrize("name", sorted(FMU_SCRIPTS))
def test_every_fmu_names_its_author_and_default_experiment(fmus, name):
    description = read_model_description(str(fmus[name]))
    assert description.author == "sma-fmu"
    experiment = description.defaultExperiment
    assert (experiment.startTime, experiment.stopTime, experiment.stepSize) == ("0.0", "10.0", "0.001")


def test_plant_interface(fmus, parameter_set):
    variables = {v.name: v for v in read_model_description(str(fmus["SmaActuator"])).modelVariables}
    assert (variables["P_in"].causality, variables["P_in"].unit) == ("input", "W")
    assert (variables["load"].causality, variables["load"].unit) == ("input", "kg")
    for name, unit in PLANT_OUTPUTS.items():
        assert (variables[name].causality, variables[name].unit) == ("output", unit)
    heating = variables["heating"]
    assert (heating.type, heating.causality, heating.variability) == ("Boolean", "output", "discrete")
    mode = variables["hysteresis_mode"]  # an Integer: 1 = continuous, 2 = switch
    assert (mode.type, mode.start) == ("Integer", "1")
    params = parameter_set.params
    assert float(variables["T_start"].start) == params.T_room
    for name in ("R_P", "a_h", "b_c", "eps_T", "nu", "A_s", "c_p", "h_c", "T_room", "mass"):
        assert variables[name].causality == "parameter"
        assert variables[name].variability == "fixed"
        assert float(variables[name].start) == getattr(params, name)


def test_feedforward_interface(fmus, parameter_set):
    variables = {v.name: v for v in read_model_description(str(fmus["SmaFeedforward"])).modelVariables}
    assert (variables["R_ref"].causality, variables["R_ref"].unit) == ("input", "ohm")
    assert (variables["load"].causality, variables["load"].unit) == ("input", "kg")
    for name, unit in FEEDFORWARD_OUTPUTS.items():
        assert (variables[name].causality, variables[name].unit) == ("output", unit)
    assert variables["saturated"].type == "Boolean"
    assert variables["adapt_to_load"].start == "true"
    params = parameter_set.params
    # alpha is not in the reference file: NaN, "not given", the thermal time constant
    assert math.isnan(float(variables["alpha"].start)) and params.alpha is None
    assert "the thermal time constant" in variables["alpha"].description
    assert float(variables["T_max"].start) == params.T_max   # the compensator bounds T_ref by it
    assert (float(variables["beta"].start), variables["beta"].unit) == (params.beta, "s")
    assert float(variables["model_load"].start) == 0.05 == params.model_load
    band = reachable_band(params.model_load, params)
    assert float(variables["R_ref"].start) == 0.5 * (band.hot + band.cold)  # mid-transformation


@pytest.mark.parametrize("name", ["SmaActuator", "SmaFeedforward"])
def test_shipped_code_imports_only_stdlib_pythonfmu_and_its_own_runtime(fmus, name):
    import sys
    stamp = code_stamp()
    with zipfile.ZipFile(fmus[name]) as archive:
        slave_module = archive.read("resources/slavemodule.txt").decode().strip()
        sources = {n: archive.read(n).decode() for n in archive.namelist()
                   if n.endswith(".py") and not n.startswith("resources/pythonfmu/")}
    stem = slave_module.rsplit('_', 1)[0]
    runtime, glue = f"{stem}_rt_{stamp}", f"{stem}_fmi_{stamp}"
    assert slave_module.endswith(stamp)
    assert any(n.startswith(f"resources/{runtime}/") for n in sources)
    assert any(n.startswith(f"resources/{glue}/") for n in sources)
    allowed = set(sys.stdlib_module_names) | {"pythonfmu", runtime, glue}
    for source_name, source in sources.items():
        roots = imported_roots(source)
        assert roots <= allowed, f"{source_name} imports {sorted(roots - allowed)}"


def test_the_two_fmus_ship_differently_named_runtimes(fmus):
    names = []
    for path in fmus.values():
        with zipfile.ZipFile(path) as archive:
            names.append({n.split("/")[1] for n in archive.namelist()
                          if n.startswith("resources/") and "_rt_" in n})
    assert len(names[0]) == len(names[1]) == 1 and names[0] != names[1]


def test_build_uses_the_given_parameter_file(tmp_path, parameter_set):
    changed = parameter_set.params.replace(a_h=71.5)
    model = write_parameter_file(tmp_path / "wire.toml", changed, "changed", "", parameter_set.meanings)
    path = build_fmu("SmaActuator", tmp_path / "out", model)
    variables = {v.name: v for v in read_model_description(str(path)).modelVariables}
    assert float(variables["a_h"].start) == 71.5


def test_cli_build_and_validate(tmp_path, capsys):
    assert main(["build", "--out", str(tmp_path)]) == 0
    assert "SmaActuator: " in capsys.readouterr().out
    assert main(["validate", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert out.count("valid (fmpy: no problems)") == len(FMU_SCRIPTS) == 5


def test_cli_validate_fails_on_a_broken_fmu(tmp_path, fmus, capsys):
    broken = tmp_path / "Broken.fmu"
    with zipfile.ZipFile(fmus["SmaActuator"]) as source, zipfile.ZipFile(broken, "w") as target:
        for item in source.infolist():
            data = source.read(item.filename)
            if item.filename == "modelDescription.xml":
                text = data.decode()
                start, end = text.index("<InitialUnknowns>"), text.index("</InitialUnknowns>")
                data = (text[:start] + text[end + len("</InitialUnknowns>"):]).encode()
            target.writestr(item, data)
    assert main(["validate", str(broken)]) == 1
    assert "InitialUnknowns does not contain the expected set" in capsys.readouterr().out
