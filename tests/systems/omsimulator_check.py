"""OMSimulator runs the exported SSP as the library's Jacobi loop: by hand, not in CI.

OMSimulator is in no package registry, so CI cannot have it, and pytest does not collect this
file by default (it does not match test_*.py). Build OMSimulator v3.0.0 (docs/systems.md),
then:

    SMA_FMU_OMSIMULATOR=/path/to/OMSimulator python -m pytest tests/systems/omsimulator_check.py

Without SMA_FMU_OMSIMULATOR the check fails (it never skips). It runs both FMU families:
pythonfmu's (``sma-fmu build``) and the native C one (``sma-fmu build --native``).
"""
import re

import pytest

from system_needs import by_hand_executable
from test_ssp_hosts import LOAD_STEP, TOLERANCE, _scenario
from sma_fmu.cosim.loop import run_library
from sma_fmu.systems.closed_loop import closed_loop
from sma_fmu.fmi.loop.wiring import loop_outputs
from sma_fmu.systems.hosts import loop_series
from sma_fmu.systems.ssp import write_ssp


@pytest.fixture(scope="module", autouse=True)
def omsimulator():
    """The executable SMA_FMU_OMSIMULATOR names; a missing one fails the check."""
    return by_hand_executable("SMA_FMU_OMSIMULATOR",
                              "an OMSimulator v3.0.0 executable (docs/systems.md)")


@pytest.fixture(params=["pythonfmu", "native"])
def family_dir(request, fmu_dir):
    """The folder of one FMU family's FMUs: pythonfmu's, or the native C family's."""
    if request.param == "pythonfmu":
        return fmu_dir
    return next(iter(request.getfixturevalue("native_fmus").values())).parent


def test_omsimulator_runs_the_ssp_as_the_library_jacobi_loop(family_dir, tmp_path):
    from sma_fmu.systems.comparison import deviation
    from sma_fmu.systems.omsimulator import run_ssp_omsimulator

    scenario = _scenario("heavy-pi+ff-adaptive", stop_time_s=2.2, load=LOAD_STEP)
    path = write_ssp(closed_loop(scenario, family_dir), tmp_path / "loop.ssp")
    samples, log = run_ssp_omsimulator(path, scenario.step_s, scenario.steps, loop_outputs(scenario.controller.feedforward))
    data = loop_series(scenario, samples, scenario.steps)
    assert deviation(data, run_library(scenario, "jacobi").data) <= TOLERANCE
    # no error line: the SSD binds no String (OMSimulator's importStartValuesHelper logs
    # "error: [...] Unknown ParameterBinding-type" for one); the packed FMUs hold the tables
    errors = [line for line in log if line.startswith("error:")
              or re.fullmatch(r"info:\s+[1-9]\d* errors", line.strip())]
    assert errors == []
