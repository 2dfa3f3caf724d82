"""The PWM drive through FMUs: the SmaPwmDriver FMU, the FMU path, the SSP and the container.

The driver FMU is checked against the runtime :class:`PwmDriver` it wraps (exactly: the
same Python runs in it) and against an independent reference, the mean of the PWM wave
sampled finely over each step. A PWM scenario (the paper's adaptive loop, 2.2 s, load step
at 0.6 s, 50 Hz PWM at 8 W peak) runs on the FMU path equal to the library path (both
hysteresis modes), in libcosim and Ecos as an SSP equal to the library's Jacobi loop, and
as a container in fmpy and libcosim
equal to the library's Gauss-Seidel loop, all to 1e-9; so do the shipped PWM scenarios on
the FMU path and in libcosim, and a PWM scenario file exported and checked by the CLI.
"""
import dataclasses
import math
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.ssp.ssd import read_ssd

from fmu_signals import STEP
from sma_fmu.cosim.loop import COLUMNS, run_library
from sma_fmu.cosim.master import run_fmus
from sma_fmu.fmi.loop.system import MissingFmuError
from sma_fmu.cosim.scenario import DriveSettings, load_scenario, resolve_scenarios
from sma_fmu.fmi.packaging.build import validate_fmus
from sma_fmu.fmi.driving.instance import FmuError, FmuInstance
from sma_fmu.runtime.pwm import PwmDriver
from sma_fmu.runtime.signals import load_from_table
from sma_fmu.systems.closed_loop import closed_loop
from sma_fmu.systems.comparison import compare_hosts, deviation
from sma_fmu.systems.container import build_container
from sma_fmu.systems.runs import run_host
from sma_fmu.systems.ssp import NAMESPACES, SSD_NAME, write_ssp

TOLERANCE = 1e-9
DISCARD, ERROR = 2, 3
PEAK = 8.0  # W
LOAD_STEP = load_from_table({"times_s": [0.0, 0.6], "values_kg": [0.0032, 0.15]})
# frequencies [Hz] against the 1-ms step: 20 steps a period, 2 steps, one step, shorter than
# a step, and periods that start inside steps
FREQUENCIES = (50.0, 500.0, 1000.0, 3333.3, 137.0)


def demand(k):
    """Demanded power [W]: below 0 W and above the peak (the duty clips), slow and fast parts."""
    t = k * STEP
    return PEAK * (0.5 + 0.7 * math.sin(2 * math.pi * 3.0 * t) + 0.2 * math.sin(2 * math.pi * 170.0 * t))


def pwm_scenario(name, frequency_Hz=50.0, peak_W=PEAK, stop_time_s=2.2, load=LOAD_STEP):
    scenario = load_scenario(resolve_scenarios([name])[0])
    return dataclasses.replace(scenario, stop_time_s=stop_time_s, load=load or scenario.load,
                               drive=DriveSettings("pwm", frequency_Hz, peak_W))


# ---------------------------------------------------------------------------- the FMU alone
def test_driver_fmu_is_valid_and_declares_its_variables_with_units(fmus):
    path = fmus["SmaPwmDriver"]
    assert validate_fmus([path]) == {path: []}
    variables = {v.name: v for v in read_model_description(str(path)).modelVariables}
    declared = {name: (v.causality, v.unit) for name, v in variables.items()}
    assert declared == {"P_demand": ("input", "W"), "P_in": ("output", "W"),
                        "frequency_Hz": ("parameter", "Hz"), "peak_W": ("parameter", "W"),
                        "wire_digest": ("local", None),   # the wire it was built with
                        # the drive limit (docs/scenarios.md, the bench)
                        "R": ("input", "ohm"), "modulation": ("parameter", None),
                        "I_max_A": ("parameter", "A"), "V_max_V": ("parameter", "V")}
    assert all(v.description for v in variables.values())
    with FmuInstance(path, "driver") as fmu:
        assert fmu.get_real(("P_in",)) == [0.0]  # after initialization: no wave yet


@pytest.mark.parametrize("frequency", FREQUENCIES)
def test_driver_fmu_is_the_runtime_driver(fmus, frequency):
    library = PwmDriver(frequency, PEAK)
    powers = []
    with FmuInstance(fmus["SmaPwmDriver"], "driver", {"frequency_Hz": frequency, "peak_W": PEAK}) as fmu:
        for k in range(600):
            fmu.set_real(("P_demand",), (demand(k),))
            fmu.step(k * STEP, STEP)
            powers.append(fmu.get_real(("P_in",))[0])
            assert powers[-1] == library.step(demand(k), k * STEP, STEP)
    assert min(powers) == 0.0 and max(powers) == PEAK and len(set(powers)) > 10


def sampled_wave_means(demands, frequency, peak, step, samples):
    """Mean power [W] of each step of the PWM wave, sampled at ``samples`` midpoints a step.

    Written from the definition, not from the runtime's code: period j starts at j / f, takes
    the duty clip(P / peak, 0, 1) of the demand P of the step in which it starts, and is on
    for the first duty / f of its length.
    """
    demands = np.asarray(demands)
    means = []
    for k in range(len(demands)):
        times = (k + (np.arange(samples) + 0.5) / samples) * step
        period = np.floor(times * frequency)
        start = period / frequency
        owner = np.floor(start / step + 1e-9).astype(int)  # the step where the period starts
        duty = np.clip(demands[owner] / peak, 0.0, 1.0)
        means.append(peak * np.mean(times - start < duty / frequency))
    return np.array(means)


@pytest.mark.parametrize("frequency", FREQUENCIES)
def test_driver_fmu_gives_the_mean_of_a_finely_sampled_wave(fmus, frequency):
    steps, samples = 200, 100_000
    demands = [demand(k) for k in range(steps)]
    with FmuInstance(fmus["SmaPwmDriver"], "driver", {"frequency_Hz": frequency, "peak_W": PEAK}) as fmu:
        powers = []
        for k, value in enumerate(demands):
            fmu.set_real(("P_demand",), (value,))
            fmu.step(k * STEP, STEP)
            powers.append(fmu.get_real(("P_in",))[0])
    reference = sampled_wave_means(demands, frequency, PEAK, STEP, samples)
    # sampling misses at most one sample's width at each switching edge of a step
    edges = 2 * (math.ceil(STEP * frequency) + 1)
    assert np.max(np.abs(np.array(powers) - reference)) <= edges * PEAK / samples


def test_state_saved_mid_period_restores_the_period_and_its_duty(fmus):
    """50 Hz, 1-ms steps: a period is 20 steps; the state is saved 7 steps into one."""
    start = {"frequency_Hz": 50.0, "peak_W": PEAK}
    library = PwmDriver(50.0, PEAK)

    def run(fmu, first, last, value):
        trace = []
        for k in range(first, last):
            fmu.set_real(("P_demand",), (value,))
            fmu.step(k * STEP, STEP)
            trace.append(fmu.get_real(("P_in",))[0])
        return trace

    with FmuInstance(fmus["SmaPwmDriver"], "driver", start) as fmu, \
            FmuInstance(fmus["SmaPwmDriver"], "other", {"frequency_Hz": 20.0, "peak_W": 1.0}) as other:
        assert run(fmu, 0, 7, 0.3 * PEAK) == [PEAK] * 6 + [0.0]  # on for 6 ms of the period
        for k in range(7):
            library.step(0.3 * PEAK, k * STEP, STEP)
        data = fmu.serialize_state(fmu.get_state())
        first = run(fmu, 7, 40, 0.8 * PEAK)
        # the period in progress keeps its duty 0.3; the next one (from step 20) takes 0.8
        assert first[:13] == [0.0] * 13 and first[13:29] == [PEAK] * 16 and first[29] == 0.0
        assert first == [library.step(0.8 * PEAK, k * STEP, STEP) for k in range(7, 40)]
        state = fmu.deserialize_state(data)
        fmu.set_state(state)
        assert fmu.get_real(("P_in",)) == [0.0]  # the output saved with the state
        assert run(fmu, 7, 40, 0.8 * PEAK) == first
        fmu.free_state(state)
        # another instance takes the state with its parameters and time
        state = other.deserialize_state(data)
        other.set_state(state)
        assert run(other, 7, 40, 0.8 * PEAK) == first
        other.free_state(state)


def _raw_instance(path, name, tmp_path):
    """fmpy's plain FMU2Slave, instantiated; with {name: variable}."""
    description = read_model_description(str(path))
    fmu = FMU2Slave(guid=description.guid, unzipDirectory=extract(str(path), str(tmp_path / name)),
                    modelIdentifier=description.coSimulation.modelIdentifier, instanceName=name)
    fmu.instantiate()
    return fmu, {v.name: v for v in description.modelVariables}


@pytest.mark.parametrize("name, value, message", [
    ("frequency_Hz", 0.0, "frequency_Hz must be > 0, got 0.0"),
    ("frequency_Hz", -50.0, "frequency_Hz must be > 0, got -50.0"),
    ("frequency_Hz", math.nan, "frequency_Hz must be finite, got nan"),
    ("peak_W", 0.0, "peak_W must be > 0, got 0.0"),
    ("peak_W", -8.0, "peak_W must be > 0, got -8.0"),
    ("peak_W", math.nan, "peak_W must be finite, got nan"),
])
def test_bad_parameters_give_fmi2error_at_exit_initialization_and_can_be_corrected(
        fmus, tmp_path, name, value, message):
    fmu, variables = _raw_instance(fmus["SmaPwmDriver"], "raw", tmp_path)
    refs = {variable.name: variable.valueReference for variable in variables.values()}
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setReal([refs[name]], [value])
    with pytest.raises(FMICallException) as raised:
        fmu.exitInitializationMode()
    assert raised.value.status == ERROR  # never fmi2Fatal: the instance lives on
    fmu.setReal([refs[name]], [20.0])   # still in Initialization Mode: correct it
    fmu.exitInitializationMode()
    fmu.setReal([refs["P_demand"]], [4.0])
    fmu.doStep(0.0, STEP)
    corrected = {n: float(variables[n].start) for n in ("frequency_Hz", "peak_W")}
    corrected[name] = 20.0
    assert fmu.getReal([refs["P_in"]]) == [PwmDriver(**corrected).step(4.0, 0.0, STEP)]
    fmu.terminate()
    fmu.freeInstance()
    with pytest.raises(FmuError, match=message) as raised:
        FmuInstance(fmus["SmaPwmDriver"], "driver", {name: value})
    assert raised.value.status == ERROR


def test_non_finite_demand_discards_the_step_and_changes_nothing(fmus):
    library = PwmDriver(137.0, PEAK)
    with FmuInstance(fmus["SmaPwmDriver"], "driver", {"frequency_Hz": 137.0, "peak_W": PEAK}) as fmu:
        for k in range(30):
            value = math.nan if k == 12 else demand(k)
            fmu.set_real(("P_demand",), (value,))
            if k == 12:
                with pytest.raises(FmuError, match="P_demand must be finite, got nan") as raised:
                    fmu.step(k * STEP, STEP)
                assert raised.value.status == DISCARD
                fmu.set_real(("P_demand",), (demand(k),))
            fmu.step(k * STEP, STEP)
            assert fmu.get_real(("P_in",)) == [library.step(demand(k), k * STEP, STEP)]


# ------------------------------------------------------------------------ the loop's paths
@pytest.mark.parametrize("name", ["load-step-pi+ff-adaptive", "load-step-continuous-pi+ff-adaptive"])
def test_fmu_path_equals_library_path_with_pwm(fmu_dir, name):
    scenario = pwm_scenario(name)
    library = run_library(scenario).data
    fmu = run_fmus(scenario, fmu_dir).data
    assert deviation(fmu, library) <= TOLERANCE
    # the plant got the PWM wave: at 50 Hz and 1-ms steps whole steps on and off
    applied = library["P"][:-1]
    assert np.count_nonzero(applied == 0.0) > 100 and np.count_nonzero(applied == PEAK) > 100
    assert not np.array_equal(applied, np.maximum(0.0, library["P_ff"] + library["P_fb"])[:-1])


@pytest.mark.parametrize("name", ["setpoints-pwm-pi+ff-adaptive", "setpoints-pwm-continuous-pi+ff-adaptive"])
def test_shipped_pwm_scenarios_on_the_fmu_path_and_in_libcosim(fmu_dir, name):
    """The first 5 s (a hold, a ramp at 4 s, the next hold): FMU path = library, SSP in
    libcosim = library Jacobi. (Containers and Ecos through the end of a hold at 7 s:
    tests/systems/test_ssp_hosts_grid.py.)"""
    scenario = dataclasses.replace(load_scenario(resolve_scenarios([name])[0]), stop_time_s=5.0)
    assert scenario.drive.pwm
    assert deviation(run_fmus(scenario, fmu_dir).data, run_library(scenario).data) <= TOLERANCE
    assert deviation(run_host("libcosim", scenario, fmu_dir).data,
                     run_library(scenario, "jacobi").data) <= TOLERANCE


def test_fmu_path_needs_the_driver_fmu(fmus, tmp_path):
    import shutil

    for name in ("SmaActuator", "SmaFeedforward"):
        shutil.copy(fmus[name], tmp_path)
    with pytest.raises(MissingFmuError, match="SmaPwmDriver.fmu not found; build the FMUs first"):
        run_fmus(pwm_scenario("load-step-pi+ff-adaptive", stop_time_s=0.01), tmp_path)


def _connections(root):
    return {(c.get("startElement"), c.get("startConnector"), c.get("endElement"), c.get("endConnector"))
            for c in root.iter(f"{{{NAMESPACES['ssd']}}}Connection")}


def test_ssp_and_container_put_the_driver_between_the_pi_and_the_plant(fmu_dir, tmp_path):
    scenario = pwm_scenario("heavy-pi", frequency_Hz=500.0, peak_W=6.5, stop_time_s=0.5, load=None)
    system = closed_loop(scenario, fmu_dir)
    assert [c.name for c in system.in_step_order()] == ["pi", "driver", "plant", "signals"]
    path = write_ssp(system, tmp_path / "pwm.ssp")
    assert read_ssd(str(path)).name == "heavy_pi"  # valid against the SSP 1.0 schemas
    with zipfile.ZipFile(path) as archive:
        assert "resources/SmaPwmDriver.fmu" in archive.namelist()
        root = ET.fromstring(archive.read(SSD_NAME))
    assert _connections(root) == {("signals", "R_ref", "pi", "R_ref"), ("signals", "load", "plant", "load"),
                                  ("pi", "P", "driver", "P_demand"), ("driver", "P_in", "plant", "P_in"),
                                  ("plant", "R", "pi", "R")}
    bindings = {(component.get("name"), parameter.get("name")): parameter[0]
                for component in root.iter(f"{{{NAMESPACES['ssd']}}}Component")
                for parameter in component.iter(f"{{{NAMESPACES['ssv']}}}Parameter")}
    frequency, peak = bindings[("driver", "frequency_Hz")], bindings[("driver", "peak_W")]
    assert (frequency.get("value"), frequency.get("unit")) == ("500.0", "Hz")
    assert (peak.get("value"), peak.get("unit")) == ("6.5", "W")
    container = build_container(system, tmp_path / "pwm.fmu")  # no unexpected builder message
    assert container.is_file()
    without = dataclasses.replace(scenario, drive=DriveSettings())
    assert "driver" not in [c.name for c in closed_loop(without, fmu_dir).components]


@pytest.fixture(scope="module")
def adaptive_pwm(fmu_dir, tmp_path_factory):
    """The paper's adaptive loop under 50 Hz PWM, 2.2 s: its SSP and its container."""
    scenario = pwm_scenario("load-step-pi+ff-adaptive")
    folder = tmp_path_factory.mktemp("pwm")
    system = closed_loop(scenario, fmu_dir)
    return scenario, {"ssp": write_ssp(system, folder / "pwm.ssp"),
                      "container": build_container(system, folder / "pwm.fmu")}


def test_ssp_in_libcosim_and_container_equal_the_library_loop_of_their_coupling(adaptive_pwm, fmu_dir):
    scenario, artifacts = adaptive_pwm
    rows = compare_hosts(scenario, fmu_dir, hosts=("libcosim", "fmpy", "libcosim-container"),
                         artifacts=artifacts)
    by_run = {row["run"]: row for row in rows if row["run"] != "library"}
    assert set(by_run) == {"libcosim (ssp)", "fmpy (container)", "libcosim-container (container)"}
    for row in by_run.values():
        assert row["deviation"] <= TOLERANCE, row
    assert by_run["libcosim (ssp)"]["coupling"] == "jacobi"
    assert by_run["fmpy (container)"]["coupling"] == "gauss-seidel"
    library = {row["coupling"]: row["rmse_ohm"] for row in rows if row["run"] == "library"}
    assert abs(library["jacobi"] - library["gauss-seidel"]) > 1e-6  # the couplings differ


def test_ssp_in_ecos_equals_the_library_jacobi_loop(adaptive_pwm, fmu_dir):
    """Ecos adds up its time (t = t + h), 1.3e-13 s off k h within 2.2 s; the driver and the
    signals take their time on the step grid k h, so every column is within 1e-9 (the power
    moved with Ecos's time by peak / h per second of shift before: docs/systems.md)."""
    scenario, artifacts = adaptive_pwm
    ecos = run_host("ecos", scenario, fmu_dir, artifacts["ssp"]).data
    library = run_library(scenario, "jacobi").data
    largest = {name: _largest_difference(ecos[name], library[name]) for name, _ in COLUMNS}
    assert max(largest.values()) <= TOLERANCE, largest


def _largest_difference(a, b):
    """Largest |a - b| of two columns; nan where both are nan (a nan on one side only: inf)."""
    a, b = a.astype(float), b.astype(float)
    both = np.isnan(a) & np.isnan(b)
    if np.any(np.isnan(a) != np.isnan(b)):
        return math.inf
    return float(np.max(np.abs(a[~both] - b[~both]), initial=0.0))


def test_pi_loop_with_pwm_faster_than_the_step_in_libcosim_and_the_container(fmu_dir):
    scenario = pwm_scenario("heavy-pi", frequency_Hz=3333.3, stop_time_s=1.0, load=None)
    rows = compare_hosts(scenario, fmu_dir, hosts=("libcosim", "fmpy"))
    assert [row["deviation"] <= TOLERANCE for row in rows] == [True] * 4


def test_cli_exports_a_pwm_scenario_and_check_passes_on_it(fmu_dir, tmp_path, capsys):
    from sma_fmu.cli import main

    text = resolve_scenarios(["load-step-pi+ff-fixed"])[0].read_text()
    assert "stop_time_s = 30.0" in text
    scenario_file = tmp_path / "pwm-fixed.toml"
    scenario_file.write_text(text.replace("stop_time_s = 30.0", "stop_time_s = 1.0")
                             + '\n[drive]\nkind = "pwm"\nfrequency_Hz = 200.0\npeak_W = 6.0\n')
    ssp, container = tmp_path / "pwm.ssp", tmp_path / "pwm.fmu"
    assert main(["export", "ssp", str(scenario_file), "--out", str(ssp), "--fmus", str(fmu_dir)]) == 0
    assert main(["export", "container", str(scenario_file), "--out", str(container),
                 "--fmus", str(fmu_dir)]) == 0
    capsys.readouterr()
    assert main(["check", str(ssp), str(container)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert not [line for line in lines if line.startswith("FAIL")]
    assert f"ok    {ssp}[resources/SmaPwmDriver.fmu]: state round trip: serialized, 20 steps " \
           "repeated bit for bit" in lines
    scenario = load_scenario(scenario_file)
    assert scenario.drive == DriveSettings("pwm", 200.0, 6.0)
    for host, artifact, coupling in (("libcosim", ssp, "jacobi"),
                                     ("libcosim-container", container, "gauss-seidel")):
        result = run_host(host, scenario, fmu_dir, artifact)
        assert deviation(result.data, run_library(scenario, coupling).data) <= TOLERANCE
