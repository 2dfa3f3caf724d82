"""The C family's wire parameter table is PARAMETER_SPECS, name by name and in order.

The C side is generated at build time (sma_fmu/fmi/packaging/parameter_table.py). A small C
program compiled from c_family/runtime/parameters.c prints what C holds: PARAMETER_SPECS
(name, section, unit, rule, required, range), then every field of WireParameters and ModelTerms of a
parameter set, by name. The test compares that view with Python's: the schema, the values
(the copies and the defaults: memory_depth, stress_max, every model term's fallback) and the
names (every parameter reaches C). A new optional parameter, added to the Python schema only,
shows up in C with its default in use, with no C file edited.
"""
import dataclasses
import math
import subprocess

import pytest

from sma_fmu.fmi.packaging import parameter_table
from sma_fmu.runtime.model_terms import TERM_DEFAULTS
from sma_fmu.runtime.parameters import (PARAMETER_SPECS, RULES, ParameterSpec, WireParameters,
                                        range_text)

from c_runtime import FLAGS, RUNTIME_DIR
from system_needs import need

pytestmark = pytest.mark.needs("gcc")

MODULES = ("parameters", "lattice", "thermal", "sma_message")
# every model term given, unlike its default (as tests/test_c_runtime_terms.py)
TERMS = dict(nu_h=150.0, nu_c=105.0, w2=0.13, a2_h=95.0, b2_h=80.0, a2_c=70.0, b2_c=45.0,
             nu2_h=45.0, nu2_c=35.0, alpha_P=1.4e-5, alpha_MF=6.6e-6, T_alpha=22.0,
             span_ratio_0=0.9, span_ratio_sat=1.12, span_stress=120.0)
PROGRAM = r"""
#include <math.h>
#include <stdio.h>
#include "parameters.h"

int main(void)
{
    static const double values[PARAM_COUNT] = {%(values)s};
    WireParameters p;
    SmaMessage message;
    int i;
    for (i = 0; i < PARAM_COUNT; i++) {
        const ParameterSpec *s = &PARAMETER_SPECS[i];
        printf("spec\t%%s\t%%s\t%%s\t%%d\t%%d\t%%.17g\t%%.17g\t%%s\n", s->name, s->section,
               s->unit, (int)s->rule, s->required, s->low, s->high, s->range);
    }
    if (wire_parameters_from_values(&p, values, &message)) {
        printf("error\t%%s\n", message.text);
        return 1;
    }
#define PRINT_FIELD(type, name) printf("field\t%%s\t%%.17g\n", #name, (double)p.name);
    SMA_WIRE_FIELDS(PRINT_FIELD)
#define PRINT_TERM(name, fallback) printf("term\t%%s\t%%.17g\n", #name, p.terms.name);
    SMA_MODEL_TERMS(PRINT_TERM)
    return 0;
}
"""


def c_view(folder, values, specs=PARAMETER_SPECS, include=None):
    """What C holds for the ``values`` {name: value} (None or absent: not given, NaN):
    {"spec": [rows], "field": {name: value}, "term": {name: value}}. ``include``: the folder
    of the generated header (default: the build's)."""
    need("gcc")
    include = parameter_table.generated_folder() if include is None else include
    numbers = ", ".join("NAN" if values.get(s.name) is None else repr(float(values[s.name]))
                        for s in specs)
    source = folder / "view.c"
    source.write_text(PROGRAM % {"values": numbers})
    program = folder / "view"
    subprocess.run(["gcc", *FLAGS, "-I", str(include), "-I", str(RUNTIME_DIR), "-o", str(program),
                    str(source), *(str(RUNTIME_DIR / f"{m}.c") for m in MODULES), "-lm"],
                   check=True, capture_output=True, text=True)
    lines = subprocess.run([str(program)], capture_output=True, text=True).stdout.splitlines()
    view = {"spec": [], "field": {}, "term": {}, "error": []}
    for line in lines:
        kind, *rest = line.split("\t")
        if kind == "spec":
            view["spec"].append(tuple(rest[:3]) + (int(rest[3]), int(rest[4]), float(rest[5]),
                                                   float(rest[6]), rest[7]))
        elif kind == "error":
            view["error"].append(rest[0])
        else:
            view[kind][rest[0]] = float(rest[1])
    return view


def _spec_rows(specs):
    rules = list(RULES)
    return [(s.name, s.section, s.unit, rules.index(s.rule), int(s.required), float(s.limits[0]),
             float(s.limits[1]), range_text(s)) for s in specs]


def _same(a, b):
    return a == b or (math.isnan(a) and math.isnan(b))


def test_c_holds_parameter_specs_name_by_name_in_order(tmp_path, params):
    view = c_view(tmp_path, params.values())
    assert view["spec"] == _spec_rows(PARAMETER_SPECS)
    assert len(view["spec"]) == len(PARAMETER_SPECS) > 40
    # every parameter is a field of C's WireParameters or a model term, none twice
    held = list(view["field"]) + list(view["term"])
    assert sorted(held) == sorted(s.name for s in PARAMETER_SPECS)


@pytest.mark.parametrize("given", ["file", "every term", "nothing optional"])
def test_c_values_and_defaults_equal_python_by_name(tmp_path, params, given):
    values = params.values()
    if given == "every term":
        values.update(TERMS, memory_depth=7, stress_max=250.0, alpha=0.4)
    elif given == "nothing optional":
        values = {s.name: values[s.name] for s in PARAMETER_SPECS if s.required}
    python = type(params).from_values(values)
    view = c_view(tmp_path, values)
    assert not view["error"]
    for name, value in view["field"].items():
        expected = getattr(python, name)
        assert _same(value, math.nan if expected is None else float(expected)), (name, value)
    for name, value in view["term"].items():
        expected = getattr(python.terms, name)
        assert _same(value, math.nan if expected is None else float(expected)), (name, value)
    if given == "nothing optional":   # the defaults were used, not the file's values
        assert view["field"]["memory_depth"] == 64 and view["field"]["stress_max"] == 300.0
        assert view["term"]["nu_h"] == view["term"]["nu2_c"] == python.nu


def test_a_new_optional_parameter_needs_no_c_edit(tmp_path, params, monkeypatch):
    """A model term added to PARAMETER_SPECS and TERM_DEFAULTS only: C's table has its row
    and C's ModelTerms its value, the fallback when not given and the value when given."""
    specs = PARAMETER_SPECS + (ParameterSpec("dummy_scale", "strain", "1", "positive", False,
                                             (0.0, 10.0)),)
    monkeypatch.setattr(parameter_table, "PARAMETER_SPECS", specs)
    monkeypatch.setattr(parameter_table, "WireParameters", dataclasses.make_dataclass(
        "WireParameters", [("dummy_scale", float, None)], bases=(WireParameters,), frozen=True))
    monkeypatch.setattr(parameter_table, "TERM_DEFAULTS",
                        TERM_DEFAULTS + (("dummy_scale", 1.0), ("dummy_copy", "dummy_scale")))
    with pytest.raises(ValueError, match="dummy_copy, not in PARAMETER_SPECS"):
        parameter_table.parameter_table_header()
    monkeypatch.setattr(parameter_table, "TERM_DEFAULTS", TERM_DEFAULTS + (("dummy_scale", 1.0),))
    (tmp_path / "generated").mkdir()
    (tmp_path / "generated" / parameter_table.TABLE_HEADER).write_text(
        parameter_table.parameter_table_header())
    for value, expected in ((None, 1.0), (2.5, 2.5)):
        view = c_view(tmp_path, {**params.values(), "dummy_scale": value}, specs,
                      tmp_path / "generated")
        assert view["spec"] == _spec_rows(specs)
        assert view["term"]["dummy_scale"] == expected
