"""One SSP, every host: what the exported package carries, and what the hosts make of it.

Pinned here: the SSD's identifiers, both vendor annotations (OSP for libcosim,
OpenModelica for OMSimulator) and the DefaultExperiment; no setting that lives only in a
String binding (choices are Integers, no String is bound: OMSimulator logs an error for
one, and every FMU carries all values as its defaults); fmpy's ``simulate_ssp``, which
binds nothing, running the scenario, compensator loops too; and
``sma-fmu check`` failing, per host, a package that a host would run differently.
OMSimulator is on no registry: its test runs only when SMA_FMU_OMSIMULATOR names the
executable (docs/systems.md); ``sma-fmu bench --only hosts`` gives its per-host table.
"""
import dataclasses
import io
import re
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest

from sma_fmu.cli import main
from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.scenario import PAPER_SET, load_scenario, resolve_scenarios
from sma_fmu.fmi.driving.instance import FmuInstance
from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.pi_control import PIController
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.signals import load_from_table
from sma_fmu.systems.check import check_file
from sma_fmu.systems.closed_loop import closed_loop
from sma_fmu.systems.fmpy_ssp import fmpy_ssp_deviation, fmpy_ssp_series, run_ssp_fmpy
from sma_fmu.systems.hosts import HostError
from sma_fmu.systems.packed import START_VALUES_ENTRY, fmu_defaults
from sma_fmu.systems.ssp import NAMESPACES, SSD_NAME, write_ssp

TOLERANCE = 1e-9
SCENARIOS = PAPER_SET + ("setpoints-pwm-pi+ff-adaptive", "setpoints-pwm-continuous-pi+ff-adaptive")
IDENTIFIER = re.compile(r"[a-zA-Z][a-zA-Z0-9_]*")
LOAD_STEP = load_from_table({"times_s": [0.0, 0.6], "values_kg": [0.0032, 0.15]})


def _tag(name):
    prefix, local = name.split(":")
    return f"{{{NAMESPACES[prefix]}}}{local}"


def _scenario(name, stop_time_s=None, load=None):
    scenario = load_scenario(resolve_scenarios([name])[0])
    return dataclasses.replace(scenario, stop_time_s=stop_time_s or scenario.stop_time_s,
                               load=load or scenario.load)


@pytest.fixture(scope="module")
def exported(fmu_dir, tmp_path_factory):
    """{name: .ssp} of the six paper scenarios and the two PWM ones, exported by the CLI."""
    folder = tmp_path_factory.mktemp("ssp")
    assert main(["export", "ssp", *SCENARIOS, "--out", str(folder), "--fmus", str(fmu_dir)]) == 0
    return {name: folder / f"{name}.ssp" for name in SCENARIOS}


def _ssd(path):
    with zipfile.ZipFile(path) as archive:
        return ET.fromstring(archive.read(SSD_NAME))


def _rewrite_ssd(source, target, change):
    """Copy the SSP ``source`` to ``target`` with ``change(text)`` applied to its SSD."""
    with zipfile.ZipFile(source) as archive, zipfile.ZipFile(target, "w") as out:
        for item in archive.infolist():
            data = archive.read(item.filename)
            if item.filename == SSD_NAME:
                data = change(data.decode()).encode()
            out.writestr(item, data)
    return target


# ----------------------------------------------------------------------- what the SSD carries
@pytest.mark.parametrize("name", SCENARIOS)
def test_the_ssd_names_are_identifiers_and_it_carries_both_annotations(exported, name):
    scenario = _scenario(name)
    root = _ssd(exported[name])
    system = root.find(_tag("ssd:System"))
    expected = name.replace("-", "_").replace("+", "_")
    assert root.get("name") == system.get("name") == expected
    assert root.get("description") == f"sma-fmu scenario {name}"
    names = [c.get("name") for c in system.iter(_tag("ssd:Component"))]
    assert all(IDENTIFIER.fullmatch(n) for n in [expected, *names])
    # OpenModelica's annotation of the system: OMSimulator's fixed-step master, the step
    master = system.find(f"{_tag('ssd:Annotations')}/{_tag('ssc:Annotation')}"
                         f"[@type='org.openmodelica']/{_tag('oms:Annotations')}/"
                         f"{_tag('oms:SimulationInformation')}/{_tag('oms:FixedStepMaster')}")
    assert master.get("description") == "oms-ma"
    assert float(master.get("stepSize")) == scenario.step_s
    # the DefaultExperiment, with the OSP annotation of the step (libcosim)
    experiment = root.find(_tag("ssd:DefaultExperiment"))
    assert (float(experiment.get("startTime")), float(experiment.get("stopTime"))) == (
        0.0, scenario.stop_time_s)
    algorithm = experiment.find(f".//{_tag('osp:FixedStepAlgorithm')}")
    assert float(algorithm.get("baseStepSize")) == scenario.step_s
    # the literal prefixes the hosts match
    text = zipfile.ZipFile(exported[name]).read(SSD_NAME).decode()
    assert "<oms:FixedStepMaster " in text and "<osp:FixedStepAlgorithm " in text


@pytest.mark.parametrize("name", SCENARIOS)
def test_the_ssd_binds_no_string_and_the_fmus_hold_every_value(exported, fmu_dir, name):
    """Choices are Integers; the SSD binds what every host reads (no String: OMSimulator
    logs an error per String binding), and every value, bound or not, is the FMU's default."""
    scenario = _scenario(name)
    system = closed_loop(scenario, fmu_dir)
    with zipfile.ZipFile(exported[name]) as archive:
        root = ET.fromstring(archive.read(SSD_NAME))
        checked = 0
        for component in root.iter(_tag("ssd:Component")):
            with zipfile.ZipFile(io.BytesIO(archive.read(component.get("source")))) as fmu:
                defaults = fmu_defaults(fmu)
                assert START_VALUES_ENTRY in fmu.namelist()
            assert not defaults.problems()
            for parameter in component.iter(_tag("ssv:Parameter")):
                kind = parameter[0].tag.rsplit("}", 1)[1]
                assert kind in ("Real", "Integer", "Boolean"), parameter.get("name")
                assert defaults.starts[parameter.get("name")][0] == kind
                checked += 1
            if component.get("name") == "signals":   # its tables: Strings, packed only
                parameters = system.component("signals").parameters
                assert {"reference", "load_profile"} <= set(parameters)
                for table in ("reference", "load_profile"):
                    assert defaults.value(table) == parameters[table]
    bindings = {(c.get("name"), p.get("name")): (p[0].tag.rsplit("}", 1)[1], p[0].get("value"))
                for c in root.iter(_tag("ssd:Component")) for p in c.iter(_tag("ssv:Parameter"))}
    mode = {"continuous": "1", "switch": "2"}[scenario.hysteresis_mode]
    assert bindings[("plant", "hysteresis_mode")] == ("Integer", mode)
    if scenario.controller.feedforward:
        assert bindings[("compensator", "inverse")] == ("Integer", "1")  # major
    assert checked == len(bindings) > 20


def test_a_packed_fmu_runs_the_scenario_with_nothing_set(exported, tmp_path, params):
    """The heavy scenario's plant (switch) and signals (0.25 kg), instantiated bare."""
    with zipfile.ZipFile(exported["heavy-pi"]) as archive:
        for name in ("SmaActuator", "SmaScenarioSignals"):
            (tmp_path / f"{name}.fmu").write_bytes(archive.read(f"resources/{name}.fmu"))
    scenario = _scenario("heavy-pi")
    with FmuInstance(tmp_path / "SmaScenarioSignals.fmu", "signals") as signals:
        assert signals.get_real(("R_ref", "load")) == [scenario.reference.value(0.0), 0.25]
    library = PlantStepper(params, scenario.T_start, "switch", 0.0)
    with FmuInstance(tmp_path / "SmaActuator.fmu", "plant") as plant:
        for k in range(400):  # heat through the transformation, then cool: switch mode
            power = 3.0 if k < 300 else 0.0
            plant.set_real(("P_in",), (power,))
            plant.step(k * 1e-3, 1e-3)
            out = library.step(power, 0.0, 1e-3)
        assert plant.get_real(("R", "T")) == [out.R, out.T]


# ------------------------------------------------------------------------- fmpy simulate_ssp
def _simulate_ssp_reference(scenario):
    """What fmpy 0.3.32's simulate_ssp computes, from the runtime steppers: Jacobi, with
    every input 0.0 in the first step (the plant's load too, from its start value; the
    compensator's R_ref, which it takes as no reference yet), the PI's P_ff at its start
    value 0 W without a compensator, the signals on the grid."""
    h, n, c = scenario.step_s, scenario.steps, scenario.controller
    plant = PlantStepper(scenario.params, scenario.T_start, scenario.hysteresis_mode, 0.0)
    pi = PIController(c.Kp, c.Ki)
    compensator = (FeedforwardStepper(scenario.compensator_params, c.alpha, c.beta, c.model_load,
                                      c.adapt_to_load, c.inverse) if c.feedforward else None)
    resistance = reference = load = power = feedforward = 0.0
    rows = []
    for k in range(n):
        command, _ = pi.sample(resistance, reference, feedforward, h)
        out = plant.step(power, load, h)
        step_ff = compensator.step(reference, load, h).P_ff if compensator else 0.0
        t = (k + 1) * h
        resistance, reference, load, power, feedforward = out.R, scenario.reference.value(t), \
            scenario.load.value(t), command, step_ff
        rows.append((reference, load, resistance, out.P, step_ff))
    columns = ("R_ref", "load", "R", "P", "P_ff")
    return {column: np.array(values) for column, values in zip(columns, zip(*rows))
            if column != "P_ff" or compensator}


@pytest.mark.parametrize("name", ["heavy-pi", "load-step-pi"])
def test_fmpy_simulate_ssp_runs_the_pi_loops_scenario(fmu_dir, tmp_path, name):
    scenario = _scenario(name, stop_time_s=2.2, load=LOAD_STEP)
    path = write_ssp(closed_loop(scenario, fmu_dir), tmp_path / f"{name}.ssp")
    series = fmpy_ssp_series(run_ssp_fmpy(path, scenario.step_s, scenario.steps))
    expected = _simulate_ssp_reference(scenario)
    for column, values in expected.items():
        assert np.max(np.abs(series[column] - values)) <= TOLERANCE, column
    # the scenario's signals, hysteresis mode and gains: the library's Jacobi loop, but for
    # fmpy's first step (every input 0.0), whose PI integral and plant power it carries on
    library = run_library(scenario, "jacobi").data
    assert np.array_equal(series["R_ref"], library["R_ref"][1:])
    assert np.array_equal(series["load"], library["load"][1:])
    assert 1e-6 < fmpy_ssp_deviation(series, library) < 0.5
    assert np.max(np.abs(series["R"][-500:] - library["R"][-500:])) < 0.01


@pytest.mark.parametrize("name", ["load-step-pi+ff-adaptive", "heavy-continuous-pi+ff-adaptive-minor-loop"])
def test_fmpy_simulate_ssp_runs_a_compensator_loop(fmu_dir, tmp_path, name):
    """Its zero first inputs give the compensator R_ref = 0 ohm: no reference yet (P_ff =
    0 W), and the loop goes on; it ends where the library's Jacobi loop does."""
    scenario = _scenario(name, stop_time_s=2.2, load=LOAD_STEP)
    path = write_ssp(closed_loop(scenario, fmu_dir), tmp_path / f"{name}.ssp")
    series = fmpy_ssp_series(run_ssp_fmpy(path, scenario.step_s, scenario.steps))
    expected = _simulate_ssp_reference(scenario)
    assert set(expected) == {"R_ref", "load", "R", "P", "P_ff"}
    for column, values in expected.items():
        assert np.max(np.abs(series[column] - values)) <= TOLERANCE, column
    # the library's Jacobi loop, but for the first step: the compensator's P_ff is 0 W
    # there, its filter starts at the second sample, the PI and the plant carry that on
    library = run_library(scenario, "jacobi").data
    assert series["P_ff"][0] == 0.0 < library["P_ff"][0]
    assert np.array_equal(series["R_ref"], library["R_ref"][1:])
    apart = np.abs(series["R"] - library["R"][1:])
    assert 1e-6 < apart.max() < 0.5
    assert np.max(np.abs(series["P_ff"][1000:] - library["P_ff"][1000:-1])) < 1e-6


# ------------------------------------------------------------------------------ sma-fmu check
def _lines(results):
    return {result.check: (result.status, result.detail) for result in results}


def test_check_reports_what_each_host_needs(exported):
    lines = _lines(check_file(exported["heavy-pi+ff-adaptive"]))
    assert lines["packed defaults"][0] == "ok"
    for host in ("libcosim 0.11", "Ecos 0.7.2", "OMSimulator 3.0.0"):
        assert lines[f"host {host}"][0] == "ok", lines[f"host {host}"]
    oms = lines["host OMSimulator 3.0.0"][1]
    assert "step 0.001 s from the org.openmodelica annotation" in oms
    assert "binds all" in oms and "--stopTime" in oms
    status, detail = lines["host fmpy 0.3.32 simulate_ssp"]
    assert status == "ok" and "compensator: R_ref = 0 ohm: P_ff = 0 W" in detail
    pi = _lines(check_file(exported["heavy-pi"]))["host fmpy 0.3.32 simulate_ssp"]
    assert pi[0] == "ok" and "0.0 on every input" in pi[1]


def _with_string_binding(source, target, value):
    """``source`` with the signals' load table bound as an ssv:String of ``value`` (JSON)."""
    binding = ('<ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues>'
               f'<ssv:ParameterSet version="1.0" name="initial"><ssv:Parameters>'
               f'<ssv:Parameter name="load_profile"><ssv:String value="{value}" />'
               '</ssv:Parameter></ssv:Parameters></ssv:ParameterSet></ssd:ParameterValues>'
               '</ssd:ParameterBinding></ssd:ParameterBindings></ssd:Component>')
    return _rewrite_ssd(source, target, lambda text: re.sub(
        r"(<ssd:Component name=\"signals\".*?)</ssd:Component>",
        lambda match: match.group(1) + binding, text, count=1, flags=re.S))


def test_check_fails_a_string_binding_omsimulator_would_log_as_an_error(exported, tmp_path):
    """The packed table, bound again as a String: libcosim, Ecos and fmpy run it; OMSimulator
    would too, but logs "Unknown ParameterBinding-type" (an error line) for it."""
    table = "{&quot;times_s&quot;:[0.0],&quot;values_kg&quot;:[0.25]}"
    path = _with_string_binding(exported["heavy-pi"], tmp_path / "string.ssp", table)
    lines = _lines(check_file(path))
    assert lines["packed defaults"][0] == "ok"
    for host in ("libcosim 0.11", "Ecos 0.7.2", "fmpy 0.3.32 simulate_ssp"):
        assert lines[f"host {host}"][0] == "ok", lines[f"host {host}"]
    status, detail = lines["host OMSimulator 3.0.0"]
    assert status == "FAIL" and "would log 1 error line(s)" in detail
    assert "Unknown ParameterBinding-type" in detail and "signals.load_profile (ssv:String)" in detail
    assert "would not run" not in detail
    assert main(["check", str(path)]) == 1


def test_check_fails_a_string_only_setting_and_names_the_hosts_it_breaks(exported, tmp_path):
    """A load table bound as a String, but not the FMU's default: OMSimulator and fmpy
    would run the FMU's table."""
    table = "{&quot;times_s&quot;:[0.0],&quot;values_kg&quot;:[0.2]}"
    path = _with_string_binding(exported["heavy-pi"], tmp_path / "edited.ssp", table)
    lines = _lines(check_file(path))
    assert lines["host libcosim 0.11"][0] == lines["host Ecos 0.7.2"][0] == "ok"
    for host in ("OMSimulator 3.0.0", "fmpy 0.3.32 simulate_ssp"):
        status, detail = lines[f"host {host}"]
        assert status == "FAIL" and "signals.load_profile would be" in detail
        assert "values_kg\":[0.25]" in detail and "values_kg\":[0.2]" in detail
    assert "it binds no String" in lines["host OMSimulator 3.0.0"][1]
    assert lines["packed defaults"][0] == "FAIL"
    assert main(["check", str(path)]) == 1


def test_check_fails_a_name_that_is_no_identifier_for_omsimulator(exported, tmp_path):
    path = _rewrite_ssd(exported["heavy-pi"], tmp_path / "named.ssp",
                        lambda text: text.replace('name="heavy_pi"', 'name="heavy-pi"'))
    lines = _lines(check_file(path))
    status, detail = lines["host OMSimulator 3.0.0"]
    assert status == "FAIL" and "SSD name 'heavy-pi' is not an identifier" in detail
    assert "system name 'heavy-pi'" in detail
    assert all(lines[f"host {h}"][0] == "ok" for h in ("libcosim 0.11", "Ecos 0.7.2"))


def test_check_fails_a_package_without_the_annotation_a_host_reads(exported, tmp_path):
    def without_oms(text):
        return re.sub(r"<ssd:Annotations>\s*<ssc:Annotation type=\"org.openmodelica\">.*?"
                      r"</ssd:Annotations>", "", text, flags=re.S)

    path = _rewrite_ssd(exported["heavy-pi"], tmp_path / "bare.ssp", without_oms)
    assert "oms:FixedStepMaster" not in zipfile.ZipFile(path).read(SSD_NAME).decode()
    lines = _lines(check_file(path))
    status, detail = lines["host OMSimulator 3.0.0"]
    assert status == "FAIL" and "no org.openmodelica annotation oms:FixedStepMaster" in detail
    assert lines["host libcosim 0.11"][0] == "ok"


# OMSimulator (on no registry, so not in CI): tests/systems/omsimulator_check.py, run by hand with
# SMA_FMU_OMSIMULATOR naming the executable (docs/systems.md).
