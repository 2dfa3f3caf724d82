"""One wire from the scenario to every FMU: a scenario that names one wire runs exactly that
wire on FMUs built from another (the masters set the whole wire, "not given" as NaN), in
both families, FMI 2.0 and 3.0, the fmpy master and the C master; an FMU that cannot take
it is refused by name, both digests named. Never a mix of two wires."""
import json
import shutil
import zipfile

import numpy as np
import pytest

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.master import run_fmus
from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.fmi.loop.system import loop_system
from sma_fmu.fmi.loop.wire_values import WireMismatchError
from sma_fmu.fmi.packaging.build import build_fmus
from sma_fmu.fmi.packaging.fmu_names import default_fmu_paths
from sma_fmu.systems.c_master import run_c_master
from sma_fmu.wire.parameter_file import load_parameter_set, write_parameter_file
from system_needs import needs

WIRE_MODELS = ["SmaActuator", "SmaFeedforward"]
SCENARIO = """
[scenario]
stop_time_s = 3.0
step_s = 0.001
{model}
[reference]
kind = "cosine"
offset_ohm = {offset}
amplitude_ohm = 3.0
frequency_hz = 0.5
[load]
times_s = [0.0, 1.5]
values_kg = [0.25, 0.1]
[controller]
kind = "pi+ff-adaptive"
[plant]
hysteresis_mode = "continuous"
"""


@pytest.fixture(scope="module")
def two_stage(tmp_path_factory, parameter_set):
    """A fitted-like wire with every kind of term the reference wire leaves out: a second
    stage, thermal expansion, the stress law, its own widths and resistances."""
    params = parameter_set.params.replace(
        w2=0.35, a2_h=110.0, a2_c=90.0, nu2_h=60.0, nu_h=120.0, alpha_P=-4.3e-5,
        alpha_MF=-5.9e-5, T_alpha=25.0, span_ratio_0=0.67, span_stress=125.0, R_P=31.0,
        a_h=75.0, alpha=0.3)
    path = write_parameter_file(tmp_path_factory.mktemp("wire") / "two_stage.toml", params,
                                "two-stage", "", parameter_set.meanings)
    return load_parameter_set(path)


def _scenario(folder, name, wire=None, offset=42.0):
    model = "" if wire is None else f'model = "{wire.path}"'
    path = folder / f"{name}.toml"
    path.write_text(SCENARIO.format(model=model, offset=offset))
    return load_scenario(path)


@pytest.fixture(scope="module")
def scenarios(tmp_path_factory, two_stage):
    """{wire: scenario} of the reference wire and the two-stage one (the same signals)."""
    folder = tmp_path_factory.mktemp("scenarios")
    return {"reference": _scenario(folder, "on-reference"),
            "two-stage": _scenario(folder, "on-two-stage", two_stage)}


def _folder(built, session_paths, folder):
    """A folder of FMUs: the wire models of ``built``, the others of the session's."""
    folder.mkdir(parents=True, exist_ok=True)
    for name, path in session_paths.items():
        shutil.copy(built.get(name, path), folder / f"{name}.fmu")
    return folder


def _same(a, b, atol):
    assert a.dtype == b.dtype and a.shape == b.shape
    for name in a.dtype.names:
        if a[name].dtype == bool:
            assert np.array_equal(a[name], b[name]), name
        else:
            np.testing.assert_allclose(a[name], b[name], rtol=0, atol=atol, equal_nan=True,
                                       err_msg=name)


def test_the_two_wires_differ_enough_that_a_mix_would_show(scenarios):
    a, b = (run_library(scenarios[w]).data for w in ("reference", "two-stage"))
    assert np.max(np.abs(a["R"] - b["R"])) > 0.5 and np.max(np.abs(a["x"] - b["x"])) > 1e-3


@pytest.mark.parametrize("family", ["python", pytest.param("native", marks=needs("gcc")),
                                    pytest.param("fmi3", marks=needs("gcc"))])
def test_each_wire_runs_exactly_on_fmus_of_the_other(family, request, scenarios, two_stage,
                                                     tmp_path_factory):
    session = {"python": "fmus", "native": "native_fmus", "fmi3": "fmi3_fmus"}[family]
    own = request.getfixturevalue(session)
    built = build_fmus(tmp_path_factory.mktemp(f"{family}-built"), two_stage.path, WIRE_MODELS,
                       native=family != "python", fmi_version=3 if family == "fmi3" else 2)
    other = _folder(built, own, tmp_path_factory.mktemp(f"{family}-other"))
    atol = 1e-9 if family == "python" else 0.0   # the C family equals the runtime bit for bit
    for wire, fmu_dir in (("two-stage", own["SmaActuator"].parent), ("reference", other)):
        scenario = scenarios[wire]
        library = run_library(scenario).data
        _same(run_fmus(scenario, fmu_dir).data, library, atol)
        if family == "native":   # the C master over the same FMUs
            _same(run_c_master(scenario, fmu_dir).data, library, atol)


def _older_build(fmu, folder, keep_nan=False):
    """A copy of ``fmu`` as an older sma-fmu built it: no wire_digest and none of the model
    terms as parameters (only its model description is changed; its parameters.json stays)."""
    import xml.etree.ElementTree as ET

    dropped = {"wire_digest", "w2", "a2_h", "b2_h", "a2_c", "b2_c", "nu2_h", "nu2_c", "alpha_P",
               "alpha_MF", "T_alpha", "span_ratio_0", "span_ratio_sat", "span_stress", "nu_h",
               "nu_c"}
    target = folder / fmu.name
    with zipfile.ZipFile(fmu) as source, zipfile.ZipFile(target, "w") as copy:
        for item in source.infolist():
            data = source.read(item.filename)
            if item.filename == "modelDescription.xml":
                root = ET.fromstring(data)
                variables = root.find("ModelVariables")
                for variable in list(variables):
                    if variable.get("name") in dropped:
                        variables.remove(variable)
                data = ET.tostring(root, encoding="UTF-8", xml_declaration=True)
            copy.writestr(item, data)
    return target


def test_an_fmu_that_cannot_take_the_wire_is_refused_naming_both(fmus, scenarios, two_stage,
                                                                  parameter_set, tmp_path):
    for name, path in fmus.items():
        if name in WIRE_MODELS:
            _older_build(path, tmp_path)
        else:
            shutil.copy(path, tmp_path)
    paths = default_fmu_paths(tmp_path)
    # its own wire: nothing it cannot take differs, so it runs
    system = loop_system(scenarios["reference"], paths)
    assert "w2" not in system.component("plant").parameters
    assert system.wire.digest == parameter_set.digest
    # another: refused, naming the FMU, both digests and files, the parameters, the way out
    with pytest.raises(WireMismatchError) as refused:
        loop_system(scenarios["two-stage"], paths)
    message = str(refused.value)
    assert "\n" not in message
    assert any(f"{model}.fmu: {model} was built from the wire" in message for model in WIRE_MODELS)
    for part in (parameter_set.digest, two_stage.digest, "w2, a2_h",
                 str(two_stage.path), "reference_wire.toml",
                 f"sma-fmu build --model {two_stage.path}"):
        assert part in message, (part, message)


def test_every_fmu_states_its_wire_and_the_system_records_the_scenarios(fmus, scenarios,
                                                                       parameter_set, two_stage):
    from fmpy import read_model_description

    for path in fmus.values():
        stated = {v.name: v for v in read_model_description(str(path)).modelVariables}["wire_digest"]
        assert (stated.causality, stated.variability, stated.start) == (
            "local", "constant", parameter_set.digest)
        with zipfile.ZipFile(path) as archive:
            assert json.loads(archive.read("resources/parameters.json"))["wire_digest"] == \
                parameter_set.digest
    system = loop_system(scenarios["two-stage"], default_fmu_paths(fmus["SmaActuator"].parent))
    assert system.wire.record() == {"file": str(two_stage.path), "digest": two_stage.digest}
    plant = system.component("plant").parameters
    assert plant["w2"] == 0.35 and plant["T_alpha"] == 25.0
    # not given in the scenario's wire and not in the FMU's either: nothing to set
    assert "span_ratio_sat" not in plant and "b2_h" not in plant


def test_runs_record_the_wire_file_and_digest(scenarios, two_stage, tmp_path):
    from sma_fmu.runtime.wire_identity import wire_digest
    from sma_fmu.studies.runs import run as study_run
    from sma_fmu.systems.runner import run_scenarios

    scenario = scenarios["two-stage"]
    rows = run_scenarios([scenario.path], tmp_path / "out", "library", progress=lambda _: None)
    recorded = {"file": str(two_stage.path), "digest": two_stage.digest}
    metrics = json.loads((tmp_path / "out" / scenario.name / "metrics.json").read_text())
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert metrics["wire"] == recorded == rows[0]["metrics"]["wire"]
    assert summary[0]["metrics"]["wire"] == recorded
    # a study's run records the wire it ran: the drawn values' digest, the base file
    drawn = study_run(scenario, {"wire.a_h": 77.0}, path="library")
    row = drawn.record()
    assert row["wire_file"] == str(two_stage.path)
    assert row["wire_digest"] == wire_digest(two_stage.params.replace(a_h=77.0)) != two_stage.digest
