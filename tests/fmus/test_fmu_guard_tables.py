"""The guard's stepComplete fast paths (fmi2GetReal, fmi2SetReal) use complete variable tables.

The slave classes run in this process (the slave scripts of ``sma_fmu/fmi/models/<Model>/`` with the
resources of a built FMU), so the guard's tables can be compared with the FMU's
modelDescription.xml: every Real variable is readable, every Real input settable, including
the last ones a slave's ``__init__`` declares.
"""
import importlib

import pytest
from fmpy import read_model_description

from sma_fmu.fmi.models import declaration
from sma_fmu.fmi.packaging.fmu_names import FMU_SCRIPTS


@pytest.mark.parametrize("name", sorted(FMU_SCRIPTS))
def test_fast_path_tables_hold_every_real_variable(unpacked, name):
    module = importlib.import_module(declaration(name).slave_module)
    slave = getattr(module, name)(instance_name="tables", resources=str(unpacked[name] / "resources"))
    reals = [v for v in read_model_description(str(unpacked[name] / "modelDescription.xml")).modelVariables
             if v.type == "Real"]
    slave.setup_experiment(0.0, None, None)
    slave.enter_initialization_mode()
    slave.exit_initialization_mode()
    guard = slave.interface.guard
    assert guard.state == "stepComplete"
    references = [v.valueReference for v in reals]
    assert slave.get_real(references) == [float(getattr(slave, v.name)) for v in reals]
    inputs = [v for v in reals if v.causality == "input"]
    slave.set_real([v.valueReference for v in inputs], [1.5] * len(inputs))
    assert [getattr(slave, v.name) for v in inputs] == [1.5] * len(inputs)
    assert guard._real_names == {v.valueReference: v.name for v in reals}
    assert guard._real_settable == {v.valueReference: v.name for v in inputs}
    assert not slave.log_queue  # nothing was refused
