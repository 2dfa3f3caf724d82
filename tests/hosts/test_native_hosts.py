"""The native (C) FMUs in the hosts users run them in (issue 25, point 5).

- fmpy's simulate_fmu runs each native FMU clean (no error message) and gives what its
  pythonfmu twin gives, under the same inputs;
- fmpy compiles each native FMU from its sources/ alone (build_platform_binary: CMake over
  the <SourceFiles> of the model description), and that binary gives what the shipped one
  gives;
- an SSP and a container exported from the native build with `sma-fmu export` run in
  libcosim, Ecos and fmpy (the hosts of tests/systems/test_systems_hosts.py) and in sma-fmu's C
  host on libcosim's C API, each equal to the library loop of its coupling to 1e-9.
fmusim, the FMU Compliance Checker and OMSimulator are in no package registry: they run by
hand (tests/hosts/fmusim_check.py, tests/hosts/compliance_checker_check.py,
tests/systems/omsimulator_check.py).
"""
import itertools
import math
import shutil
import zipfile

import numpy as np
import pytest
from fmpy import extract, simulate_fmu

from native_twins import Instance
from sma_fmu.cli import main
from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios
from sma_fmu.fmi.driving.description import read_description
from sma_fmu.systems.c_host import run_c_host
from sma_fmu.systems.comparison import compare_hosts
from system_needs import needs

pytestmark = needs("gcc")
TOLERANCE = 1e-12
_NAMES = itertools.count()
STOP_S = 2.0


def _times():
    return np.linspace(0.0, STOP_S, 201)


# inputs per model: {input: values at _times()}, moving enough to exercise each model
INPUTS = {
    "SmaActuator": lambda t: {"P_in": 2.0 + 1.5 * np.sin(np.pi * t), "load": np.where(t < 1.0, 0.05, 0.15)},
    "SmaFeedforward": lambda t: {"R_ref": 42.0 + 4.0 * np.cos(np.pi * t), "load": np.full_like(t, 0.05)},
    "SmaPiController": lambda t: {"R_ref": np.full_like(t, 42.0), "R": 42.0 + np.sin(3.0 * t),
                                  "P_ff": np.full_like(t, 1.0)},
    "SmaPwmDriver": lambda t: {"P_demand": 2.0 + 1.5 * np.sin(5.0 * t)},
    "SmaScenarioSignals": lambda t: {},
}


def _input(model, path):
    names = {v.name for v in read_description(path).modelVariables if v.causality == "input"}
    values = INPUTS[model](_times())
    assert set(values) <= names, (model, names)
    if not values:
        return None
    table = np.zeros(len(_times()), dtype=[("time", float)] + [(n, float) for n in values])
    table["time"] = _times()
    for name, column in values.items():
        table[name] = column
    return table


def _simulate(path, model):
    """(result, [(status, message)] logged) of fmpy's simulate_fmu over STOP_S at 1 ms.

    The instance is made with the permanent logger of tests/support/native_twins.py: fmpy's own
    ``simulate_fmu(logger=...)`` leaves its process-wide logger proxy pointing at a freed
    callback, and a later FMU that logs in the same process crashes it (either family)."""
    instance = Instance(path, f"simulate-{model}-{next(_NAMES)}")
    try:
        result = simulate_fmu(instance.folder, stop_time=STOP_S, step_size=1e-3,
                              output_interval=1e-3, input=_input(model, path),
                              model_description=read_description(path), fmu_instance=instance.fmu,
                              terminate=False)
        return result, list(instance.log)
    finally:
        instance.close()


def _largest_difference(a, b):
    worst = 0.0
    for name in a.dtype.names:
        x, y = np.asarray(a[name], float), np.asarray(b[name], float)
        assert x.shape == y.shape, name
        assert np.array_equal(np.isnan(x), np.isnan(y)), name
        x, y = np.nan_to_num(x), np.nan_to_num(y)
        scale = np.maximum(np.maximum(np.abs(x), np.abs(y)), 1e-300)
        worst = max(worst, float(np.max(np.abs(x - y) / scale)))
    return worst


@pytest.mark.parametrize("model", list(INPUTS))
def test_fmpy_simulates_each_native_fmu_clean_and_as_its_twin(native_fmus, fmus, model):
    native, messages = _simulate(native_fmus[model], model)
    python, _ = _simulate(fmus[model], model)
    assert [m for m in messages if m[0] >= 2] == []  # no discard, error or fatal
    assert native.size == round(STOP_S / 1e-3) + 1
    assert _largest_difference(native, python) <= TOLERANCE
    moving = [n for n in native.dtype.names if n != "time" and np.ptp(np.asarray(native[n], float)) > 0]
    assert moving, f"{model}: no output moved"


@pytest.mark.parametrize("model", list(INPUTS))
def test_fmpy_compiles_each_native_fmu_from_its_sources_alone(native_fmus, model, tmp_path):
    from fmpy.build import build_platform_binary

    folder = extract(str(native_fmus[model]), unzipdir=str(tmp_path / model))
    shutil.rmtree(f"{folder}/binaries")
    description = read_description(native_fmus[model])
    assert description.buildConfigurations[0].sourceFileSets[0].sourceFiles  # <SourceFiles>
    (tmp_path / "build").mkdir()
    build_platform_binary(folder, build_dir=str(tmp_path / "build"))
    built = list((tmp_path / model / "binaries").rglob(f"{model}.so"))
    assert len(built) == 1, built
    repacked = shutil.make_archive(str(tmp_path / f"{model}-rebuilt"), "zip", folder)
    rebuilt, messages = _simulate(shutil.move(repacked, tmp_path / f"{model}-rebuilt.fmu"), model)
    shipped, _ = _simulate(native_fmus[model], model)
    assert [m for m in messages if m[0] >= 2] == []
    assert _largest_difference(rebuilt, shipped) <= TOLERANCE


@pytest.fixture(scope="module")
def exported(native_fmus, tmp_path_factory):
    """An SSP and a container of the PWM set-point loop (all five native FMUs), 6 s, written
    by `sma-fmu export` from the native build."""
    folder = tmp_path_factory.mktemp("exported")
    text = resolve_scenarios(["setpoints-pwm-pi+ff-adaptive"])[0].read_text()
    assert "stop_time_s = 30.0" in text
    scenario_file = folder / "pwm-short.toml"
    scenario_file.write_text(text.replace("stop_time_s = 30.0", "stop_time_s = 6.0"))
    fmu_dir = native_fmus["SmaActuator"].parent
    ssp, container = folder / "loop.ssp", folder / "loop.fmu"
    assert main(["export", "ssp", str(scenario_file), "--fmus", str(fmu_dir), "--out", str(ssp)]) == 0
    assert main(["export", "container", str(scenario_file), "--fmus", str(fmu_dir), "--out",
                 str(container)]) == 0
    return load_scenario(scenario_file), fmu_dir, {"ssp": ssp, "container": container}


def test_the_exports_carry_the_native_fmus(exported):
    _, _, artifacts = exported
    with zipfile.ZipFile(artifacts["ssp"]) as ssp:
        packed = sorted(n for n in ssp.namelist() if n.endswith(".fmu"))
        assert len(packed) == 5
        for name in packed:
            with zipfile.ZipFile(ssp.open(name)) as fmu:
                names = fmu.namelist()
            assert any(n.startswith("sources/") for n in names), name
            assert not any("pythonfmu" in n or n.endswith(".py") for n in names), name


def test_ssp_and_container_of_native_fmus_match_the_library_in_every_host(exported):
    scenario, fmu_dir, artifacts = exported
    rows = compare_hosts(scenario, fmu_dir, artifacts=artifacts)
    runs = {row["run"]: row for row in rows if row["run"] != "library"}
    assert set(runs) == {"libcosim (ssp)", "ecos (ssp)", "fmpy (container)",
                         "libcosim-container (container)"}
    for row in runs.values():
        assert row["deviation"] <= 1e-9, row
        assert math.isfinite(row["rmse_ohm"])


def test_the_c_host_runs_the_native_ssp_and_container(exported):
    scenario, _, artifacts = exported
    last = {c: run_library(scenario, c).data[-1] for c in ("gauss-seidel", "jacobi")}
    system = run_c_host("ssp", artifacts["ssp"], scenario.step_s, scenario.steps)
    container = run_c_host("fmu", artifacts["container"], scenario.step_s, scenario.steps)
    for name in ("R", "T", "x"):
        assert system[f"plant.{name}"] == pytest.approx(last["jacobi"][name], abs=1e-9)
        assert container[f"fmu.{name}"] == pytest.approx(last["gauss-seidel"][name], abs=1e-9)
    assert system["driver.P_in"] >= 0.0  # the PWM driver ran in the system
