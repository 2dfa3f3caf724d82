"""The front's ``sma_fmu_step`` export (fmi/python_family/front/combined_step.c): fmi2SetReal + fmi2DoStep +
fmi2GetReal (+ fmi2GetBoolean) in one call, which the fmpy master uses when an FMU has it.

It must be nothing but those FMI calls: the same results to the last bit, the same
statuses, the same messages, the same stage named when one fails.
"""
import math

import numpy as np
import pytest

from sma_fmu.cosim.master import FmuPlant, LeanStep, run_fmus
from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.files.package_data import shipped_file
from sma_fmu.fmi.driving.instance import FmuError, FmuInstance
from sma_fmu.fmi.loop.system import loop_system

STEP = 1e-3


def test_the_master_uses_the_export_of_an_fmu_with_the_front(fmus):
    with FmuInstance(fmus["SmaActuator"], "export") as fmu:
        assert LeanStep(fmu, ("P_in",), ("T",)).combined is not None
        assert LeanStep(fmu, ("P_in",), ("T",), combined=False).combined is None


@pytest.mark.parametrize("controller", ["pi", "pi+ff-adaptive"])
def test_one_call_gives_the_closed_loop_of_the_separate_calls(fmus, controller):
    scenario = load_scenario(shipped_file("scenarios", f"load-step-{controller}.toml"))
    one = run_fmus(scenario, fmus["SmaActuator"].parent).data
    separate = run_fmus(scenario, fmus["SmaActuator"].parent, combined=False).data
    assert len(one) == scenario.steps + 1
    for name in one.dtype.names:
        assert np.array_equal(one[name], separate[name], equal_nan=True), name


def _failing_steps(path, combined):
    """(status, message) of plant steps: a bad power, a bad load, a bad time, a good step,
    then one after fmi2Terminate."""
    scenario = load_scenario(shipped_file("scenarios", "load-step-pi.toml"))
    plant = FmuPlant(loop_system(scenario, {"SmaActuator": path}, only=("plant",)).component("plant"),
                     combined=combined)
    results = []
    try:
        for args in ((0.0, math.nan, 0.05, STEP), (0.0, 1.0, -1.0, STEP), (0.5, 1.0, 0.05, STEP),
                     (0.0, 1.0, 0.05, STEP), "terminate", (STEP, 1.0, 0.05, STEP)):
            if args == "terminate":
                plant.fmu._fmu.terminate()
                continue
            try:
                results.append(("ok", plant.step(*args)))
            except FmuError as error:
                results.append((error.status, str(error)))
        return results
    finally:
        plant.close()


def test_a_failing_step_reports_the_same_call_status_and_message(fmus):
    one = _failing_steps(fmus["SmaActuator"], None)
    separate = _failing_steps(fmus["SmaActuator"], False)
    assert one == separate
    statuses = [status for status, _ in one]
    assert statuses == [2, 2, 3, "ok", 3]  # discards, a refused step, a step, a refused set
    assert "fmi2DoStep failed (discard)" in one[0][1] and "P_in" in one[0][1]
    assert "fmi2DoStep failed (discard)" in one[1][1] and "load" in one[1][1]
    assert "fmi2DoStep failed (error)" in one[2][1]
    assert "set P_in, load failed (error)" in one[4][1]
