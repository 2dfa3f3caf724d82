"""The FMI 3.0 C-family FMUs' x86_64-windows binaries step under wine64 as x86_64-linux does.

A small FMI 3.0 host (tests/support/fmi3_walk_host.c) is built twice, with gcc and with mingw-w64
(-Wall -Wextra -Wpedantic -Werror), and steps the plant and the PWM driver through the same
deterministic input walk: every call returns fmi3OK, nothing is logged at warning or worse,
and every output of the windows run equals the linux run to 1e-12 of the output's scale
(the FMI 2.0 tolerance: mingw-w64's exp/log/pow may differ from glibc's in the last bit).
The largest difference is printed (pytest -s).
"""
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description

from sma_fmu.fmi.c_common import include_flags

from system_needs import need, needs, wine_command

pytestmark = needs("gcc", "mingw-w64")
TOLERANCE = 1e-12
HOST = Path(__file__).parents[1] / "support" / "fmi3_walk_host.c"
CASES = {"SmaActuator": ("P_in", ["R", "T", "x", "xi_P", "xi_M", "xi_F", "P"]),
         "SmaPwmDriver": ("P_demand", ["P_in"])}
FLAGS = ["-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O2", *include_flags()]


@pytest.fixture(scope="module")
def unpacked(tmp_path_factory):
    from sma_fmu.fmi.packaging.build import build_fmus
    root = tmp_path_factory.mktemp("fmi3win")
    paths = build_fmus(root / "fmus", names=list(CASES), native=True, fmi_version=3)
    folders = {}
    for name, path in paths.items():
        with zipfile.ZipFile(path) as archive:
            archive.extractall(root / name)
        folders[name] = root / name
    return folders


@pytest.fixture(scope="module")
def hosts(tmp_path_factory):
    from sma_fmu.fmi.hosts import c_compiler, windows_compiler
    folder = tmp_path_factory.mktemp("fmi3hosts")
    linux, windows = folder / "walk", folder / "walk.exe"
    subprocess.run([*c_compiler(), *FLAGS, "-o", str(linux), str(HOST), "-ldl", "-lm"], check=True)
    subprocess.run([*windows_compiler(), *FLAGS, "-o", str(windows), str(HOST)], check=True)
    return linux, windows


def _arguments(folder, name, steps, windows=False):
    """The host's arguments; under wine, the folder as Windows sees it (Z: is /)."""
    description = read_model_description(str(folder))
    references = {v.name: v.valueReference for v in description.modelVariables}
    source, outputs = CASES[name]
    where = "Z:" + str(folder).replace("/", "\\") if windows else str(folder)
    return [where, name, description.instantiationToken, str(steps), "0.001",
            str(references[source]), *(str(references[o]) for o in outputs)]


def _run(command, environment=None):
    result = subprocess.run(command, capture_output=True, text=True, timeout=900, env=environment)
    problems = [line for line in result.stderr.splitlines() if not line.startswith("log 0 ")]
    assert result.returncode == 0 and problems == [], (result.returncode, result.stderr[-2000:])
    return np.array([[float(x) for x in line.split()] for line in result.stdout.splitlines()])


@pytest.mark.parametrize("name", list(CASES))
def test_windows_binaries_step_as_linux(unpacked, hosts, wine, name):
    steps = 20000
    linux = _run([str(hosts[0]), *_arguments(unpacked[name], name, steps)])
    windows = _run([wine_command(), str(hosts[1]), *_arguments(unpacked[name], name, steps, True)],
                   wine)
    assert linux.shape == windows.shape == (steps, len(CASES[name][1]))
    scale = np.maximum(np.abs(linux).max(axis=0), 1e-300)
    largest = (np.abs(windows - linux).max(axis=0) / scale)
    print(f"{name}: largest windows/linux difference relative to scale: "
          f"{dict(zip(CASES[name][1], largest.tolist()))}")
    assert (largest <= TOLERANCE).all()
    assert np.ptp(linux, axis=0).max() > 0  # the walk moves the outputs
