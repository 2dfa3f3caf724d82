"""A ctypes front over the C PlantStepper (sma_fmu/fmi/c_family/runtime/plant.c) for
tests/native/test_c_runtime_plant.py: parameters and steppers on the heap, refusals as ValueError,
saved states in both layouts, message normalization, and the random power/load walks."""
import ctypes
import math
import re

import pytest

from sma_fmu.runtime.parameters import PARAMETER_SPECS
from sma_fmu.runtime.plant import STATE_FORMAT
from sma_fmu.runtime.thermal import power_to_reach, step_decay

from c_runtime import StateDoubles, load_with_signatures, with_reversals

RUNTIME = ("sma_message", "checks", "state_entries", "lattice", "thermal", "phases",
           "constant_load", "minor_loops", "validity", "parameters", "plant")
OUTPUTS = ("R", "T", "x", "xi_P", "xi_M", "xi_F", "P", "heating")

# a test-only front over the C API: objects on the heap, errors and warnings as text
SHIM = r"""
#include <stdlib.h>
#include <string.h>
#include "plant.h"
#include "state_entries.h"

static void copy_error(char *error, const SmaMessage *m) { memcpy(error, m->text, 512); }
void *params_new(const double *values, const char *source, char *error) {
    SmaMessage m; WireParameters *p = malloc(sizeof *p);
    if (wire_parameters_from_values_source(p, values, source, &m)) {
        copy_error(error, &m); free(p); return NULL;
    }
    return p;
}
void params_free(void *p) { free(p); }
void *plant_new(const void *params, int has_start, double start, const char *mode,
                double load, char *error) {
    SmaMessage m; PlantStepper *s = malloc(sizeof *s);
    if (plant_stepper_init(s, params, has_start ? &start : NULL, mode, load, &m)) {
        copy_error(error, &m); free(s); return NULL;
    }
    return s;
}
void plant_delete(void *s) { plant_stepper_free(s); free(s); }
void plant_outputs(const void *stepper, double *out, char *warning) {
    const PlantStepper *s = stepper; const PlantOutputs *o = &s->outputs;
    out[0] = o->R; out[1] = o->T; out[2] = o->x; out[3] = o->xi_P; out[4] = o->xi_M;
    out[5] = o->xi_F; out[6] = o->P; out[7] = o->heating;
    memcpy(warning, s->warning, sizeof s->warning);
}
int plant_step(void *s, double power, double load, double h, char *error) {
    SmaMessage m;
    if (plant_stepper_step(s, power, load, h, &m)) { copy_error(error, &m); return 1; }
    return 0;
}
int load_resistance(const void *params, double t, double load, int direction, double *out,
                    char *error) {
    SmaMessage m;
    if (constant_load_resistance(t, load, direction, params, out, &m)) {
        copy_error(error, &m); return 1;
    }
    return 0;
}
double entropy(double xi_p, double xi_m, double xi_f, double cells) {
    PhaseFractions f; f.xi_P = xi_p; f.xi_M = xi_m; f.xi_F = xi_f;
    return configurational_entropy(f, cells);
}
int direction_of_text(const char *text, int *sign, char *error) {
    SmaMessage m;
    if (direction_sign_of_text(text, NULL, sign, &m)) { copy_error(error, &m); return 1; }
    return 0;
}
int format_check(const char *found, char *error) {
    SmaMessage m;
    if (check_format(found, PLANT_STATE_FORMAT, "plant state", &m)) {
        copy_error(error, &m); return 1;
    }
    return 0;
}
size_t plant_size(const void *s) { return plant_stepper_state_size(s); }
void plant_write(const void *s, double *out) { plant_stepper_state_write(s, out); }
int plant_read(void *s, const double *in, size_t count, char *error) {
    SmaMessage m;
    if (plant_stepper_state_read(s, in, count, &m)) { copy_error(error, &m); return 1; }
    return 0;
}
"""

D, P, I, S, C = (ctypes.c_double, ctypes.c_void_p, ctypes.c_int, ctypes.c_size_t,
                 ctypes.c_char_p)
DP = ctypes.POINTER(ctypes.c_double)
SIGNATURES = {
    "params_new": (P, [DP, C, C]), "params_free": (None, [P]),
    "plant_new": (P, [P, I, D, C, D, C]), "plant_delete": (None, [P]),
    "plant_outputs": (None, [P, DP, C]), "plant_step": (I, [P, D, D, D, C]),
    "load_resistance": (I, [P, D, D, I, DP, C]), "entropy": (D, [D, D, D, D]),
    "direction_of_text": (I, [C, ctypes.POINTER(ctypes.c_int), C]),
    "format_check": (I, [C, C]), "plant_size": (S, [P]), "plant_write": (None, [P, DP]), "plant_read": (I, [P, DP, S, C]),
}


def c_values(values):
    """A name -> value mapping as the C values[] array (PARAMETER_SPECS order, None = NaN)."""
    numbers = [values.get(spec.name) for spec in PARAMETER_SPECS]
    return (ctypes.c_double * len(numbers))(*[math.nan if v is None else float(v)
                                             for v in numbers])


class CParameters:
    """WireParameters in C; a refusal raises ValueError with the C message."""

    def __init__(self, lib, values, source="<parameters>"):
        error = ctypes.create_string_buffer(512)
        self.lib, self.pointer = lib, lib.params_new(c_values(values), source.encode(), error)
        if not self.pointer:
            raise ValueError(error.value.decode())

    def __del__(self):
        if getattr(self, "pointer", None):
            self.lib.params_free(self.pointer)


class CPlant(StateDoubles):
    """The C PlantStepper with Python's method names; refusals raise ValueError."""

    STATE_CALLS = ("plant_size", "plant_write", "plant_read")

    def __init__(self, lib, params, T_start=None, mode="continuous", load=0.0):
        self.lib, self.cparams = lib, CParameters(lib, params.values())
        error = ctypes.create_string_buffer(512)
        self.pointer = lib.plant_new(self.cparams.pointer, T_start is not None,
                                     0.0 if T_start is None else T_start,
                                     None if mode is None else mode.encode(), load, error)
        if not self.pointer:
            raise ValueError(error.value.decode())
        self._read()

    def __del__(self):
        if getattr(self, "pointer", None):
            self.lib.plant_delete(self.pointer)

    def _read(self):
        out, warning = (ctypes.c_double * 8)(), ctypes.create_string_buffer(512)  # plant.h: warning[512]
        self.lib.plant_outputs(self.pointer, out, warning)
        self.warning = warning.value.decode() or None
        return tuple(out[:7]) + (bool(out[7]),)

    @property
    def outputs(self):
        return self._read()

    def step(self, power, load, step_size):
        error = ctypes.create_string_buffer(512)
        if self.lib.plant_step(self.pointer, power, load, step_size, error):
            raise ValueError(error.value.decode())
        return self._read()


def doubles_of(state):
    """Python's state() dict in the C layout (plant.h)."""
    return with_reversals([float(state[key]) for key in (
        "temperature", "direction", "load", "xi_MF", "xi_P", "power")], state["reversals"])


def state_of(values):
    """The C layout as Python's state() dict."""
    count = int(values[6])
    return {"format": STATE_FORMAT, "temperature": values[0], "direction": int(values[1]),
            "load": values[2], "xi_MF": values[3], "xi_P": values[4], "power": values[5],
            "reversals": [[values[7 + 2 * i], values[8 + 2 * i]] for i in range(count)]}


def same(a, b):
    """Bit-for-bit equal sequences (repr tells -0.0 from 0.0 and round-trips exactly)."""
    return len(a) == len(b) and all(repr(x) == repr(y) for x, y in zip(a, b))


_NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+(?:\.\d*)?(?:[eE][-+]?\d+)?|inf|nan)(?![\w.])")


def normalized(text):
    """A message with every number as Python's repr of its float ('-1' and '-1.0' agree)."""
    return _NUMBER.sub(lambda match: repr(abs(float(match.group())))
                       if match.group().lstrip("+-") == "nan" else repr(float(match.group())),
                       text)


def refusal(call):
    """The message of the ValueError ``call`` raises."""
    with pytest.raises(ValueError) as caught:
        call()
    return str(caught.value)


# ---------------------------------------------------------------- the walks

def power_walk(rng, params, steps):
    """Instructions (kind, value, load [kg], h [s]): kind "T" asks for the power that takes
    the Python plant to that temperature [degC] in one step, "P" is a power [W]. Nested
    reversals of shrinking amplitude, returns to exact earlier levels, noise (many tiny
    loops), excursions past validity.T_max, load changes (some past load_max, some every
    step), zero and negative power, several step sizes."""
    load, h = rng.choice([0.0, 0.05, 0.15]), rng.choice([0.01, 0.02, 0.05])
    history, plan = [], []
    if rng.random() < 0.5:                     # held power: T may stay put (direction kept)
        plan += [("P", 0.0, load, h)] * rng.randint(1, 4)
    while len(plan) < steps:
        kind = rng.random()
        if kind < 0.35:                        # nested reversals of shrinking amplitude
            deep = rng.random() < 0.1          # sometimes deeper than a memory of 64
            centre, amplitude = rng.uniform(35.0, 130.0), rng.uniform(3.0, 50.0)
            sign = rng.choice((1, -1))
            for _ in range(rng.randint(60, 90) if deep else rng.randint(2, 14)):
                goal = centre + sign * amplitude
                plan += [("T", goal, load, h)] * rng.randint(1, 3)
                history.append(goal)
                amplitude *= rng.uniform(0.95, 0.98) if deep else rng.uniform(0.4, 0.95)
                sign = -sign
        elif kind < 0.45 and history:          # back exactly to earlier levels
            for _ in range(rng.randint(1, 5)):
                plan += [("T", rng.choice(history), load, h)] * rng.randint(1, 3)
        elif kind < 0.55:                      # powers as they come: 0, negative, ramps
            for _ in range(rng.randint(1, 30)):
                plan.append(("P", rng.choice([0.0, -1.0, rng.uniform(0.0, 6.0),
                                              rng.uniform(-2.0, 8.0)]), load, h))
        elif kind < 0.6:                       # past validity.T_max and back
            plan += [("T", params.T_max + rng.uniform(-5.0, 40.0), load, h)] * rng.randint(1, 4)
        elif kind < 0.72:                      # a load change (sometimes past load_max)
            load = rng.choice([0.0, 0.02, 0.05, 0.1, 0.25, 0.5, rng.uniform(0.0, 0.3),
                               params.load_max * rng.uniform(1.0, 1.5)])
        elif kind < 0.8:                       # a load that changes every step
            for _ in range(rng.randint(5, 90)):
                load = abs(load + rng.gauss(0.0, 0.02))
                plan.append(("T", rng.uniform(30.0, 140.0), load, h))
        elif kind < 0.85:                      # another step size
            h = rng.choice([0.01, 0.02, 0.05, 1e-3, rng.uniform(1e-4, 0.2)])
        else:                                  # noise around the last level: tiny loops
            level = history[-1] if history else rng.uniform(40.0, 120.0)
            plan += [("T", level + rng.gauss(0.0, 0.5), load, h)
                     for _ in range(rng.randint(2, 40))]
    return plan[:steps]


def power_of(instruction, python):
    kind, value, load, h = instruction
    if kind == "P":
        return value, load, h
    params = python.params
    decay = step_decay(h, params.tau_th)
    return power_to_reach(python.temperature, value, params.T_room, params.K_th, decay), load, h


def load_library(folder):
    """The runtime and the shim built into ``folder``, with the shim's signatures set."""
    return load_with_signatures(RUNTIME, folder, SHIM, SIGNATURES)
