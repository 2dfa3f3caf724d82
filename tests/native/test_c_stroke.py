"""The C stroke map (c_family/runtime/stroke.c) against runtime/stroke.py: the same doubles
(R_ref, stroke, temperature, clamped) for random strokes, loads and directions on the
reference wire (closed form) and on the Flexinol fit (two stages, thermal expansion: the
secant search), strokes beyond reach at both ends included, and the refusal of a negative
load in the same words."""
import ctypes
import random

import pytest

from sma_fmu.files.package_data import shipped_file
from sma_fmu.runtime.stroke import StrokeMap, start_length
from sma_fmu.wire.parameter_file import load_parameter_set

import c_feedforward
from c_runtime import load_with_signatures
from system_needs import needs

pytestmark = needs("gcc")
POINTS = 3000
DP, IP = c_feedforward.DP, c_feedforward.IP

SHIM = c_feedforward.SHIM + r"""
#include "stroke.h"
void *stroke_new(const void *params, double start_length) {
    StrokeMap *map = malloc(sizeof *map); stroke_map_init(map, params, start_length); return map;
}
void stroke_free(void *map) { free(map); }
int stroke_target(void *map, double stroke, double load, int direction, double *out,
                  int *clamped, char *error) {
    SmaMessage m; StrokeTarget t;
    if (stroke_map_target(map, stroke, load, direction, &t, &m)) { copy_error(error, &m); return 1; }
    out[0] = t.R_ref; out[1] = t.stroke; out[2] = t.temperature; *clamped = t.clamped; return 0;
}
"""
SIGNATURES = {**c_feedforward.SIGNATURES,
              "stroke_new": (ctypes.c_void_p, [ctypes.c_void_p, ctypes.c_double]),
              "stroke_free": (None, [ctypes.c_void_p]),
              "stroke_target": (ctypes.c_int, [ctypes.c_void_p, ctypes.c_double,
                                               ctypes.c_double, ctypes.c_int, DP, IP,
                                               ctypes.c_char_p])}


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    return load_with_signatures(c_feedforward.RUNTIME + ("stroke",),
                                tmp_path_factory.mktemp("stroke"), SHIM, SIGNATURES)


def _wire(name):
    return load_parameter_set(shipped_file("models", name)).params


@pytest.mark.parametrize("wire,start_load,loads", [("reference_wire.toml", 0.0032, (0.0, 0.2)),
                                                   ("flexinol_fit.toml", 0.1, (0.05, 0.35))])
def test_the_c_stroke_map_gives_pythons_doubles(lib, wire, start_load, loads):
    params = _wire(wire)
    x0 = start_length(params, None, start_load)
    python = StrokeMap(params, x0)
    cparams = c_feedforward.CParameters(lib, params)
    cmap = lib.stroke_new(cparams.pointer, x0)
    out, clamped = (ctypes.c_double * 3)(), ctypes.c_int()
    error = ctypes.create_string_buffer(512)
    rng, seen = random.Random(53), set()
    try:
        for k in range(POINTS):
            # a held call now and then (the kept target), else a new stroke in -10 ... 50 mm
            stroke = rng.uniform(-10e-3, 50e-3) if k % 7 or not k else stroke_before
            load = rng.choice(loads + (rng.uniform(*loads),))
            direction = rng.choice((1, -1))
            stroke_before = stroke
            target = python.target(stroke, load, direction)
            assert lib.stroke_target(cmap, stroke, load, direction, out, ctypes.byref(clamped),
                                     error) == 0, error.value
            assert (out[0], out[1], out[2], bool(clamped.value)) == tuple(target), k
            seen.add(target.clamped)
    finally:
        lib.stroke_free(cmap)
    assert seen == {True, False}   # both inside and beyond reach


def test_the_c_stroke_map_refuses_a_load_as_python_does(lib, params):
    x0 = start_length(params, None, 0.0)
    cparams = c_feedforward.CParameters(lib, params)
    cmap = lib.stroke_new(cparams.pointer, x0)
    out, clamped = (ctypes.c_double * 3)(), ctypes.c_int()
    error = ctypes.create_string_buffer(512)
    try:
        with pytest.raises(ValueError) as raised:
            StrokeMap(params, x0).target(5e-3, -1.0, 1)
        assert lib.stroke_target(cmap, 5e-3, -1.0, 1, out, ctypes.byref(clamped), error) == 1
        # the same words; the C repr of the number is the shorter "-1"
        assert str(raised.value).startswith(error.value.decode()) and "load must be >= 0" in str(
            raised.value)
    finally:
        lib.stroke_free(cmap)
