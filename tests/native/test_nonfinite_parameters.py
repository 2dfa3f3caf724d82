"""A NaN or an infinite parameter is refused by name at fmi2ExitInitializationMode, the same in
both families (issue 38, F6). Inside the C runtime NaN used to mean "not given", so the native
SmaFeedforward took its default for a NaN `alpha`, and both wire FMUs for `stress_max`; now a
parameter carries a "given" flag (parameters.h: wire_parameters_from_given)."""
import math

import pytest
from fmpy import read_model_description

from native_twins import Instance

pytestmark = pytest.mark.needs("gcc")

MODELS = ["SmaActuator", "SmaFeedforward", "SmaPiController", "SmaPwmDriver"]


def _outcome(path, name, parameter, value):
    """(status of fmi2ExitInitializationMode, its last message without the instance name)."""
    fmu = Instance(path, name)
    try:
        fmu.fmu.setupExperiment(startTime=0.0)
        fmu.fmu.enterInitializationMode()
        assert fmu.set(parameter, value) == 0
        status = fmu.call("exitInitializationMode")[0]
        return status, fmu.log[-1][1].replace(name, "<name>") if fmu.log else ""
    finally:
        fmu.close()


def _real_parameters(path):
    return [v.name for v in read_model_description(str(path)).modelVariables
            if v.causality == "parameter" and v.type == "Real"]


@pytest.mark.parametrize("model", MODELS)
def test_a_nan_parameter_is_refused_by_name_in_both_families(fmus, native_fmus, model):
    for parameter in _real_parameters(fmus[model]):
        python = _outcome(fmus[model], f"py-{model}-{parameter}", parameter, math.nan)
        native = _outcome(native_fmus[model], f"c-{model}-{parameter}", parameter, math.nan)
        assert python[0] == native[0] == 3, (parameter, python, native)
        assert parameter in native[1] and "nan" in native[1], native
        assert python[1] == native[1], parameter


@pytest.mark.parametrize("model,parameter", [("SmaFeedforward", "alpha"),
                                             ("SmaFeedforward", "stress_max"),
                                             ("SmaActuator", "stress_max")])
@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_optional_parameters_set_non_finite_are_refused_not_defaulted(fmus, native_fmus, model,
                                                                       parameter, value):
    """The three the campaign found: optional in a parameter file, always given in an FMU."""
    native = _outcome(native_fmus[model], f"c-{parameter}-{value}", parameter, value)
    python = _outcome(fmus[model], f"py-{parameter}-{value}", parameter, value)
    assert native[0] == python[0] == 3
    assert f".{parameter} = {value!r} must be" in native[1]
    assert python[1] == native[1]
