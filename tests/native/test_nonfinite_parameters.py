"""A NaN or an infinite parameter is refused by name at fmi2ExitInitializationMode, the same in
both families (issue 38, F6), but NaN in an optional wire parameter without a number as
default (alpha, nu_h, nu_c, the model terms: wire_use.NULLABLE), which means "not given" in
both. Inside the C runtime NaN used to mean "not given" for any optional parameter, so the
native FMUs took the default for a NaN `stress_max` where the Python ones refused it; now a
parameter carries a "given" flag (parameters.h: wire_parameters_from_given, sma_wire.c)."""
import math

import pytest
from fmpy import read_model_description

from native_twins import Instance
from sma_fmu.fmi.python_family.slave_support.wire_use import NULLABLE

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
    for parameter in [p for p in _real_parameters(fmus[model]) if p not in NULLABLE]:
        python = _outcome(fmus[model], f"py-{model}-{parameter}", parameter, math.nan)
        native = _outcome(native_fmus[model], f"c-{model}-{parameter}", parameter, math.nan)
        assert python[0] == native[0] == 3, (parameter, python, native)
        assert parameter in native[1] and "nan" in native[1], native
        assert python[1] == native[1], parameter


@pytest.mark.parametrize("model,parameter,value", [
    ("SmaFeedforward", "alpha", math.inf), ("SmaFeedforward", "alpha", -math.inf),
    ("SmaActuator", "w2", math.inf), ("SmaFeedforward", "stress_max", math.nan),
    ("SmaFeedforward", "stress_max", math.inf), ("SmaActuator", "stress_max", math.nan),
    ("SmaActuator", "stress_max", -math.inf)])
def test_optional_parameters_set_non_finite_are_refused_not_defaulted(fmus, native_fmus, model,
                                                                       parameter, value):
    """The three the campaign found: an infinity is never "not given", nor is a NaN where the
    model has a number as default (stress_max)."""
    native = _outcome(native_fmus[model], f"c-{parameter}-{value}", parameter, value)
    python = _outcome(fmus[model], f"py-{parameter}-{value}", parameter, value)
    assert native[0] == python[0] == 3
    assert f".{parameter} = {value!r} must be" in native[1]
    assert python[1] == native[1]


def _started(path, name, values):
    """The outputs after initialization with ``values`` set (exit must succeed)."""
    fmu = Instance(path, name)
    try:
        assert fmu.start(values) == 0, fmu.log[-1:]
        return fmu.values()
    finally:
        fmu.close()


@pytest.mark.parametrize("model", ["SmaActuator", "SmaFeedforward"])
def test_nan_in_an_optional_parameter_is_not_given_in_both_families(fmus, native_fmus, model,
                                                                   parameter_set):
    """NaN takes back what a host set: the outputs are those of the parameter not given."""
    optional = [p for p in _real_parameters(fmus[model]) if p in NULLABLE]
    assert {"alpha", "w2", "a2_h", "nu_h", "T_alpha", "span_stress"} & set(optional)
    inputs = {"load": 0.1, "T_start": 60.0} if model == "SmaActuator" else {"load": 0.1, "R_ref": 45.0}
    given = {"w2": 0.3, "a2_h": 120.0, "a2_c": 95.0, "alpha_P": -4e-5, "T_alpha": 25.0}
    for family, paths in (("py", fmus), ("c", native_fmus)):
        default = _started(paths[model], f"{family}-{model}-default", inputs)
        changed = _started(paths[model], f"{family}-{model}-given", {**inputs, **given})
        taken_back = _started(paths[model], f"{family}-{model}-nan",
                              {**inputs, **given, **{name: math.nan for name in optional}})
        assert changed != default and taken_back == default, family
