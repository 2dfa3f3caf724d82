"""Every wire parameter has a plausible range in the schema (runtime/parameters.py,
PARAMETER_SPECS' ``limits``), and a value outside it is refused naming the parameter, its unit
and the range: by the parameter-file reader, the runtime and the C runtime alike (the C table
is generated from the schema). The FMUs of both families, FMI 2.0 and 3.0, refuse it when it
is set as a parameter or read from resources: tests/test_parameter_ranges_fmus.py.

The fuzz campaign's findings pinned here: R_M, R_F, l_F of 1e30 were accepted (R up to
9e307 ohm, x = 5e29 m); a_h = -1e30 was refused as "hysteresis centre ... below 0 K" without
naming a_h; stress_max = inf as "must be > 0" (not "finite")."""
import math

import pytest

from sma_fmu.identification.isobaric.starts import BOUNDS
from sma_fmu.identification.isobaric.centres import DEFAULT_TEMPERATURES
from sma_fmu.runtime.constant_load import branch_constants
from sma_fmu.runtime.constants import COOLING, HEATING
from sma_fmu.runtime.parameters import (PARAMETER_SPECS, RULES, ParameterError, range_text,
                                        value_in_range)
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.wire.geometry import GEOMETRY_INPUTS
from sma_fmu.wire.parameter_file import load_parameters

SPEC = {spec.name: spec for spec in PARAMETER_SPECS}


def _outside(spec):
    """Values just outside ``spec``'s range and far outside it (the unit slips)."""
    low, high = spec.limits
    values = [high * 10.0 if high > 0 else 1.0, 1e30, math.inf, math.nan]
    if low < 0:
        values += [low * 10.0, -1e30, -math.inf]
    return values


def _message(spec, value):
    requirement = ("a whole number in " if spec.rule == "depth" else
                   "in " if math.isfinite(value) else "a finite number in ")
    return (f"parameter {spec.section}.{spec.name} = {value!r} must be {requirement}"
            f"{range_text(spec)} [{spec.unit}]")


def test_every_parameter_has_a_range_that_agrees_with_its_rule():
    for spec in PARAMETER_SPECS + GEOMETRY_INPUTS:
        low, high = spec.limits
        assert math.isfinite(low) and math.isfinite(high) and low < high, spec
        if spec.rule in ("positive", "nonnegative", "fraction", "margin"):
            assert low == 0.0, spec          # the rule's own end
        assert spec.rule in RULES, spec
    assert SPEC["theta"].limits == (0.0, 1.0) and SPEC["saturation_margin"].limits == (0.0, 0.5)
    assert range_text(SPEC["R_P"]) == "(0, 100000]" and range_text(SPEC["w2"]) == "[0, 1)"
    assert range_text(SPEC["a_h"]) == "[-273.15, 1000]"


def test_what_a_fit_or_the_command_line_may_reach_lies_inside_the_ranges():
    """The isobaric fit's own bounds (identification/isobaric/starts.py, centres.py) and the fit's
    --stress (0, 2000] MPa and --load [0, 10] kg: a fitted file is never refused."""
    low, high = DEFAULT_TEMPERATURES   # the centres' bounds (the measured range, within these)
    lead = high - low   # the heating lead over the cooling centre: LinearCentres.bounds("gap0")
    inside = {"a_c": ("a_c", (low, high)), "w2": ("w2", BOUNDS["w2"]), "alpha_P": ("alpha_P", BOUNDS["alpha_P"]),
              "alpha_MF": ("alpha_MF", BOUNDS["alpha_MF"]),
              "span_ratio_0": ("span_ratio_0", BOUNDS["span_ratio_0"]),
              "span_stress": ("span_stress", BOUNDS["span_stress"]),
              "a_h": ("a_h", (low, high + lead)),
              "R_MF": ("R_M", (1e-3, 1e4)), "stress": ("stress_max", (1e-3, 2000.0)),
              "load": ("model_load", (0.0, 10.0))}
    for what, (name, (low, high)) in inside.items():
        assert value_in_range(SPEC[name], low) and value_in_range(SPEC[name], high), what


def test_the_shipped_and_a_fitted_wire_lie_inside_their_ranges(params, tmp_path):
    for spec in PARAMETER_SPECS:
        value = getattr(params, spec.name)
        assert value is None or value_in_range(spec, value), spec.name
    # the NiTiHf fit's terms (docs/identification.md): 2.9x the reference centres, s0 0.098
    fitted = params.replace(a_h=151.57, a_c=121.69, b_h=84.35, b_c=75.56, w2=0.377,
                            a2_h=155.62, a2_c=128.12, alpha_P=1.15e-5, alpha_MF=-1.83e-6,
                            span_ratio_0=0.0983, span_stress=300.5, T_max=309.0, stress_max=600.0)
    assert fitted.terms.two_stage


@pytest.mark.parametrize("name", [spec.name for spec in PARAMETER_SPECS])
def test_a_value_outside_its_range_is_refused_naming_parameter_unit_and_range(params, name):
    spec = SPEC[name]
    for value in _outside(spec):
        with pytest.raises(ParameterError) as caught:
            params.replace(**{name: value})
        assert _message(spec, value) in str(caught.value), (value, str(caught.value))


@pytest.mark.parametrize("name,value", [("R_M", 1e30), ("R_F", 1.7976931348623157e308),
                                        ("l_F", 1e30), ("x0", 800.0), ("R_P", 33e3 * 1e3)])
def test_the_parameter_file_reader_refuses_a_unit_slip_naming_file_key_and_range(
        tmp_path, name, value):
    """R_P in milliohm, x0 in mm: the file is refused when it is read."""
    from sma_fmu.wire.parameter_file import default_parameter_file
    spec = SPEC[name]
    lines = []
    for line in default_parameter_file().read_text(encoding="utf-8").splitlines():
        if line.split("=")[0].strip() == name and "value =" in line:
            start = line.index("value = ") + len("value = ")
            line = f"{line[:start]}{value!r}{line[line.index(',', start):]}"
        lines.append(line)
    path = tmp_path / "slip.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with pytest.raises(ParameterError) as caught:
        load_parameters(path)
    assert str(caught.value) == f"{path}: {_message(spec, value)}"


@pytest.mark.parametrize("name,value", [("density", 6.45e6), ("linear_density", 1e30),
                                        ("density", -1.0)])
def test_a_geometry_input_outside_its_range_is_refused_by_name(tmp_path, name, value):
    from sma_fmu.wire.parameter_file import default_parameter_file
    text = default_parameter_file().read_text(encoding="utf-8")
    unit = {"density": "kg/m3", "linear_density": "kg/m"}[name]
    text = text.replace("[geometry]\n", f'[geometry]\n{name} = {{ value = {value!r}, unit = '
                                        f'"{unit}", meaning = "x" }}\n')
    path = tmp_path / "geometry.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ParameterError) as caught:
        load_parameters(path)
    assert f"parameter geometry.{name} = {value!r} must be in " in str(caught.value)


def test_the_two_misleading_messages_name_the_parameter_and_say_finite(params):
    with pytest.raises(ParameterError) as caught:
        params.replace(a_h=-1e30)
    assert "parameter hysteresis.a_h = -1e+30 must be in [-273.15, 1000] [degC]" in str(caught.value)
    assert "0 K" not in str(caught.value)
    with pytest.raises(ParameterError) as caught:
        params.replace(stress_max=math.inf)
    assert "parameter validity.stress_max = inf must be a finite number in (0, 2000] [MPa]" \
        in str(caught.value)


@pytest.mark.parametrize("direction,words", [(HEATING, "hysteresis centre a_h + b_h f = -300.0"),
                                             (COOLING, "hysteresis centre a_c + b_c f = -300.0")])
def test_a_centre_below_0_k_names_the_parameters_it_is_made_of(params, direction, words):
    """In range each, a_d + b_d f below 0 K at a load: the message says which centre."""
    wire = params.replace(a_h=-200.0, b_h=-1000.0, a_c=-200.0, b_c=-1000.0)
    with pytest.raises(ValueError) as caught:
        branch_constants(0.1, direction, wire)
    assert f"{words} degC at load 0.1 kg is below 0 K" in str(caught.value)


@pytest.mark.needs("gcc")
def test_the_c_runtime_refuses_alike_naming_the_same_range(tmp_path, params):
    from c_plant import CParameters, CPlant, load_library, normalized, refusal
    lib = load_library(tmp_path)
    values, count = params.values(), 0
    for spec in PARAMETER_SPECS:
        for value in _outside(spec):
            if not spec.required and math.isnan(value):
                continue                                # C: NaN = an optional one not given
            bad = {**values, spec.name: value}
            python = refusal(lambda: type(params).from_values(bad, source="w"))
            c = refusal(lambda: CParameters(lib, bad, "w"))
            assert normalized(c) == normalized(python), (spec.name, value, c, python)
            assert "must be" in c and f"{range_text(spec)} [{spec.unit}]" in c
            count += 1
    assert count > 200
    wire = params.replace(a_h=-200.0, b_h=-1000.0)
    python = refusal(lambda: PlantStepper(wire, None, "continuous", 0.1))
    c = refusal(lambda: CPlant(lib, wire, load=0.1))
    assert "hysteresis centre a_h + b_h f" in c and normalized(c) == normalized(python)
