"""The bench scenarios in every path: the same seed gives the same run, to the bit.

A noisy, current-limited load-step (the limit made binding: 0.3 A) and its PWM twin (a limited
on-power) run on the library path, in the fmpy master over the pythonfmu, the native and the
FMI 3.0 FMUs (the PI and its sensor in Python, the driver and its limit in the FMU), and in
the C master over both FMI 2.0 families (the sensor in the PI FMU): every column of every row
equal. Another seed changes the run; the shipped bench scenarios carry the documented chain.
"""
import dataclasses

import numpy as np
import pytest

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.master import run_fmus
from sma_fmu.cosim.noise_seeds import with_seed
from sma_fmu.cosim.scenario import DriveSettings, load_scenario, resolve_scenarios, scenario_names
from sma_fmu.systems.c_master import run_c_master
from system_needs import needs

PROFILES = ("load-step", "load-step-continuous", "heavy", "heavy-continuous")
KINDS = ("pi", "pi+ff-fixed", "pi+ff-adaptive", "pi+ff-adaptive-minor-loop")


def _scenarios():
    bench = load_scenario(resolve_scenarios(["load-step-bench-pi+ff-adaptive"])[0])
    bench = dataclasses.replace(bench, stop_time_s=1.5)
    limited = dataclasses.replace(bench, drive=dataclasses.replace(bench.drive, I_max_A=0.3))
    pwm = dataclasses.replace(bench, drive=DriveSettings("pwm", 50.0, 8.0, I_max_A=0.3, V_max_V=24.0))
    return {"linear": limited, "pwm": pwm}


def _same(a, b, label):
    for name in a.dtype.names:
        assert np.array_equal(a[name], b[name], equal_nan=a.dtype[name] != bool), (label, name)


def test_the_shipped_bench_scenarios_carry_the_documented_chain():
    names = {f"{profile}-bench-{kind}" for profile in PROFILES for kind in KINDS}
    assert names <= set(scenario_names())
    for name in names:
        scenario = load_scenario(resolve_scenarios([name])[0])
        plain = load_scenario(resolve_scenarios([name.replace("-bench", "")])[0])
        assert scenario.sensor.noise_ohm_rms == 0.05 and scenario.sensor.bits == 16
        assert scenario.sensor.full_scale_ohm / 2 ** 16 == pytest.approx(1e-3, rel=1e-12)
        assert (scenario.drive.kind, scenario.drive.I_max_A, scenario.drive.V_max_V) == \
            ("power", 0.5, 24.0)
        assert scenario.controller == plain.controller
        assert scenario.hysteresis_mode == plain.hysteresis_mode
        assert scenario.reference.as_table() == plain.reference.as_table()
        assert scenario.load.as_table() == plain.load.as_table()
        assert scenario.group == plain.group + "-bench"


def test_another_seed_changes_the_run_and_the_same_seed_does_not():
    scenario = _scenarios()["linear"]
    first, again = run_library(scenario).data, run_library(scenario).data
    _same(first, again, "library twice")
    other = run_library(with_seed(scenario, 2)).data
    assert not np.array_equal(first["P_fb"], other["P_fb"], equal_nan=True)
    assert np.array_equal(first["R_ref"], other["R_ref"])


@needs("gcc")
@pytest.mark.parametrize("kind", ["linear", "pwm"])
def test_every_path_gives_the_librarys_run(kind, fmus, native_fmus, fmi3_fmus):
    scenario = _scenarios()[kind]
    library = run_library(scenario).data
    resistance, power = library["R"][:-1], library["P"][:-1]
    assert np.all(power <= 0.09 * resistance * (1 + 1e-15))
    assert np.any(power >= 0.09 * resistance * (1 - 1e-12))      # the limit binds
    folders = {"pythonfmu": fmus["SmaActuator"].parent,
               "native": native_fmus["SmaActuator"].parent,
               "fmi3": fmi3_fmus["SmaActuator"].parent}
    for family, folder in folders.items():
        _same(library, run_fmus(scenario, folder).data, f"fmpy master, {family}")
    for family in ("pythonfmu", "native"):
        _same(library, run_c_master(scenario, folders[family]).data, f"C master, {family}")
