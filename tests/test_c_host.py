"""The FMUs in a C host: libcosim (Open Simulation Platform) driven from a C program.

The host process is not Python: libcosim loads the FMU with the FMI Library; pythonfmu's
binary needs libpython preloaded (LD_PRELOAD), as the README explains.
"""
import os
import re
import shutil
import subprocess
import sysconfig
from pathlib import Path

import pytest
from fmpy import read_model_description

from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.plant import PlantStepper

HERE = Path(__file__).parent

libcosimpy = pytest.importorskip("libcosimpy", reason="libcosimpy (test extra) provides libcosimc")


def _libpython():
    name = sysconfig.get_config_var("INSTSONAME") or sysconfig.get_config_var("LDLIBRARY")
    return Path(sysconfig.get_config_var("LIBDIR")) / name


@pytest.fixture(scope="module")
def cosim_run(tmp_path_factory):
    assert shutil.which("gcc"), "gcc is needed to build the C host"
    lib_dir = Path(libcosimpy.__file__).parent / "libcosimc"
    exe = tmp_path_factory.mktemp("c_host") / "cosim_run"
    subprocess.run(["gcc", "-O1", "-Wall", "-Werror", "-o", str(exe), str(HERE / "c_host" / "cosim_run.c"),
                    f"-L{lib_dir}", "-lcosimc", f"-Wl,-rpath,{lib_dir}"], check=True)
    return exe


def _run(exe, fmu, step, steps, assignments, outputs, preload=True):
    refs = {v.name: v.valueReference for v in read_model_description(str(fmu)).modelVariables}
    env = dict(os.environ)
    if preload:
        env["LD_PRELOAD"] = str(_libpython())
    else:
        env.pop("LD_PRELOAD", None)
    args = [str(exe), str(fmu), repr(step), str(steps)]
    args += [f"{refs[name]}={value!r}" for name, value in assignments.items()]
    args += ["--"] + [str(refs[name]) for name in outputs]
    result = subprocess.run(args, capture_output=True, text=True, env=env, timeout=120)
    values = {}
    names = {ref: name for name, ref in refs.items()}
    for line in result.stdout.splitlines():  # libcosim also logs to stdout
        match = re.fullmatch(r"(\d+)=(\S+)", line.strip())
        if match:
            values[names[int(match.group(1))]] = float(match.group(2))
    return result, values


def test_plant_fmu_runs_in_libcosim(cosim_run, fmus, params):
    result, values = _run(cosim_run, fmus["SmaActuator"], 1e-3, 5000,
                          {"P_in": 2.6, "load": 0.05}, ["R", "T", "xi_F"])
    assert result.returncode == 0, result.stderr[-2000:]
    library = PlantStepper(params, load=0.05)
    for _ in range(5000):
        out = library.step(2.6, 0.05, 1e-3)
    # libcosim passes h as (1e6 ns) * 1e-9 s: equal up to that rounding
    assert values["T"] == pytest.approx(out.T, abs=1e-9)
    assert values["R"] == pytest.approx(out.R, abs=1e-9)
    assert values["xi_F"] == pytest.approx(out.xi_F, abs=1e-12)
    assert out.R < 48.0  # the run went into the transformation


def test_feedforward_fmu_runs_in_libcosim(cosim_run, fmus, params):
    result, values = _run(cosim_run, fmus["SmaFeedforward"], 1e-3, 500,
                          {"R_ref": 42.0, "load": 0.15}, ["P_ff", "T_ref"])
    assert result.returncode == 0, result.stderr[-2000:]
    library = FeedforwardStepper(params)
    for _ in range(500):
        out = library.step(42.0, 0.15, 1e-3)
    assert values["T_ref"] == pytest.approx(out.T_ref, abs=1e-9)
    assert values["P_ff"] == pytest.approx(out.P_ff, abs=1e-9)


def test_without_preloaded_libpython_the_fmu_binary_cannot_load(cosim_run, fmus):
    result, values = _run(cosim_run, fmus["SmaActuator"], 1e-3, 10, {}, ["R"], preload=False)
    assert result.returncode != 0 and not values
    assert "undefined symbol" in result.stdout + result.stderr  # libcosim logs to stdout
