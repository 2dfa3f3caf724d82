"""A ctypes front over the C compensator (c_family/runtime feedforward, sensing,
reachable_band) for the equality tests, and the random R_ref/load walks that drive it.

:data:`SHIM` is test-only C over the runtime API (parameters and steppers on the heap, errors
and warnings as text); :class:`CStepper` has the Python FeedforwardStepper's method names;
:func:`doubles_of` writes Python's state() dict in the C layout (feedforward.h).
"""
import ctypes
import math
import re

from sma_fmu.runtime.parameters import PARAMETER_SPECS
from sma_fmu.runtime.reachable_band import reachable_band

from c_runtime import StateDoubles, load_with_signatures, with_reversals

MINE = ("reachable_band", "sensing", "phase_lag", "shaping", "feedforward")
RUNTIME = ("sma_message", "checks", "state_entries", "lattice", "thermal", "phases",
           "constant_load", "minor_loops", "validity", "parameters", "reachable_band",
           "sensing", "phase_lag", "plant", "shaping", "feedforward")

# a test-only front over the C API: parameters and steppers on the heap, errors as text
SHIM = r"""
#include <stdlib.h>
#include <string.h>
#include "feedforward.h"
#include "reachable_band.h"
#include "sensing.h"

static void copy_error(char *error, const SmaMessage *m) { memcpy(error, m->text, 512); }

void *params_new(const double *values, char *error) {
    SmaMessage m; WireParameters *p = malloc(sizeof *p);
    if (wire_parameters_from_values(p, values, &m)) { copy_error(error, &m); free(p); return NULL; }
    return p;
}
void params_free(void *p) { free(p); }

void *ff_new(const void *params, double alpha, double beta, double model_load, int adapt,
             const char *inverse, const char *shaping, double power_cap, double lead,
             char *error) {
    SmaMessage m; FeedforwardStepper *s = malloc(sizeof *s);
    if (feedforward_stepper_init(s, params, alpha, beta, model_load, adapt, inverse, shaping,
                                 power_cap, &m)
        || feedforward_stepper_set_anticipation(s, lead, &m)) {
        copy_error(error, &m); feedforward_stepper_free(s); free(s); return NULL;
    }
    return s;
}
void ff_free(void *s) { feedforward_stepper_free(s); free(s); }
static void put(const FeedforwardOutputs *o, double *out, int *saturated) {
    out[0] = o->P_ff; out[1] = o->T_ref; *saturated = o->saturated;
}
int ff_step(void *s, double r, double load, double h, double *out, int *saturated,
            char *warning, char *error) {
    SmaMessage m; FeedforwardOutputs o; FeedforwardStepper *f = s;
    if (feedforward_stepper_step(f, r, load, h, &o, &m)) { copy_error(error, &m); return 1; }
    put(&o, out, saturated); memcpy(warning, f->warning, sizeof f->warning); return 0;
}
int ff_initial(void *s, double r, double load, double *out, int *saturated, char *error) {
    SmaMessage m; FeedforwardOutputs o;
    if (feedforward_stepper_initial_outputs(s, r, load, &o, &m)) {
        copy_error(error, &m); return 1;
    }
    put(&o, out, saturated); return 0;
}
size_t ff_state_size(const void *s) { return feedforward_stepper_state_size(s); }
void ff_state_write(const void *s, double *out) { feedforward_stepper_state_write(s, out); }
int ff_state_read(void *s, const double *in, size_t count, char *error) {
    SmaMessage m;
    if (feedforward_stepper_state_read(s, in, count, &m)) { copy_error(error, &m); return 1; }
    return 0;
}
int band(const void *params, double load, double *out, char *error) {
    SmaMessage m; ResistanceBand b;
    if (reachable_band(load, params, &b, &m)) { copy_error(error, &m); return 1; }
    out[0] = b.hot; out[1] = b.cold; return 0;
}
int sense(const void *params, double r, double load, int direction, const double *points,
          size_t count, double *temperature, int *saturated, char *error) {
    SmaMessage m; SensedTemperature t; ReversalPoint stack[64]; size_t i;
    for (i = 0; i < count && i < 64; i++) { stack[i].temperature = points[2 * i];
                                            stack[i].xi_MF = points[2 * i + 1]; }
    if (sense_temperature(r, load, direction, params, stack, count, &t, &m)) {
        copy_error(error, &m); return 1;
    }
    *temperature = t.temperature; *saturated = t.saturated; return 0;
}
"""

D, P, I, S, C = (ctypes.c_double, ctypes.c_void_p, ctypes.c_int, ctypes.c_size_t,
                 ctypes.c_char_p)
DP, IP = ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_int)
SIGNATURES = {
    "params_new": (P, [DP, C]), "params_free": (None, [P]),
    "ff_new": (P, [P, D, D, D, I, C, C, D, D, C]), "ff_free": (None, [P]),
    "ff_step": (I, [P, D, D, D, DP, IP, C, C]), "ff_initial": (I, [P, D, D, DP, IP, C]),
    "ff_state_size": (S, [P]), "ff_state_write": (None, [P, DP]),
    "ff_state_read": (I, [P, DP, S, C]), "band": (I, [P, D, DP, C]),
    "sense": (I, [P, D, D, I, DP, S, DP, IP, C]),
}


class CParameters:
    """WireParameters in C from a Python WireParameters (PARAMETER_SPECS order)."""

    def __init__(self, lib, params):
        values = [getattr(params, spec.name) for spec in PARAMETER_SPECS]
        array = (ctypes.c_double * len(values))(*[math.nan if v is None else float(v)
                                                 for v in values])
        error = ctypes.create_string_buffer(512)
        self.lib, self.pointer = lib, lib.params_new(array, error)
        assert self.pointer, error.value.decode()

    def __del__(self):
        self.lib.params_free(self.pointer)


class CStepper(StateDoubles):
    """The C FeedforwardStepper with Python's method names; refusals raise ValueError."""

    STATE_CALLS = ("ff_state_size", "ff_state_write", "ff_state_read")

    def __init__(self, lib, cparams, params, alpha=None, beta=None, model_load=None,
                 adapt_to_load=True, inverse="major", shaping="none", power_cap=None,
                 anticipation=0.0):
        self.lib, self.cparams = lib, cparams   # cparams outlives the stepper
        error = ctypes.create_string_buffer(512)
        self.pointer = lib.ff_new(
            cparams.pointer, params.phase_lag_alpha if alpha is None else alpha,
            params.beta if beta is None else beta,
            params.model_load if model_load is None else model_load, int(adapt_to_load),
            None if inverse is None else inverse.encode(),
            None if shaping is None else shaping.encode(),
            math.nan if power_cap is None else power_cap, anticipation, error)
        if not self.pointer:
            raise ValueError(error.value.decode())
        self._out, self._saturated = (ctypes.c_double * 2)(), ctypes.c_int()
        self._warning = ctypes.create_string_buffer(1024)  # feedforward.h: warning[1024]
        self._error = ctypes.create_string_buffer(512)
        self.warning = None

    def __del__(self):
        if getattr(self, "pointer", None):
            self.lib.ff_free(self.pointer)

    def _outputs(self):
        return self._out[0], self._out[1], bool(self._saturated.value)

    def step(self, reference, load, step_size):
        if self.lib.ff_step(self.pointer, reference, load, step_size, self._out, self._saturated,
                            self._warning, self._error):
            raise ValueError(self._error.value.decode())
        self.warning = self._warning.value.decode() or None
        return self._outputs()

    def initial_outputs(self, reference, load):
        if self.lib.ff_initial(self.pointer, reference, load, self._out, self._saturated,
                               self._error):
            raise ValueError(self._error.value.decode())
        return self._outputs()


def doubles_of(state):
    """Python's state() dict in the C layout (feedforward.h): None as NaN; the
    anticipation's three after its own doubles; a shaped compensator's model wire after
    them (plant.h's layout)."""
    def number(value):
        return math.nan if value is None else float(value)
    own = with_reversals([
        float(state["direction"]), number(state["previous_reference"]),
        number(state["previous_temperature"]), number(state["previous_fraction"]),
        number(state["filter"]["previous_input"]), number(state["filter"]["previous_output"]),
        number(state["previous_exponent"]), number(state["previous_slope"])],
        state["reversals"])
    if "anticipation" in state:
        own += [number(state["anticipation"][key]) for key in ("earlier", "previous", "held")]
    if "model" not in state:
        return own
    model = state["model"]
    return own + with_reversals([model[key] for key in ("temperature", "direction", "load",
                                                         "xi_MF", "xi_P", "power")],
                                model["reversals"])


def same_doubles(a, b):
    return len(a) == len(b) and all(x == y or (math.isnan(x) and math.isnan(y))
                                    for x, y in zip(a, b))


_NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+(?:\.\d*)?(?:[eE][-+]?\d+)?|inf|nan)(?![\w.])")


def normalized(text):
    """A message with every number as Python's repr of its float ('-1' and '-1.0' agree)."""
    return _NUMBER.sub(lambda match: repr(float(match.group())), text)


def reference_walk(rng, params, steps):
    """(R_ref [ohm], load [kg], h [s]) samples: nested reversals, returns to exact earlier
    levels, holds, saturation at both ends, load changes, a few varied steps."""
    load, h = rng.choice([0.0, 0.05, 0.15]), 1e-3
    history = []
    samples = []
    if rng.random() < 0.5:                      # unconnected start
        samples += [(0.0, load, h)] * rng.randint(1, 3)
    while len(samples) < steps:
        band = reachable_band(load, params)
        hot, cold, span = band.hot, band.cold, band.cold - band.hot
        kind = rng.random()
        if kind < 0.35:                         # nested reversals of shrinking amplitude
            centre = rng.uniform(hot + 0.2 * span, cold - 0.2 * span)
            amplitude = rng.uniform(0.05, 0.45) * span
            sign = rng.choice((1, -1))
            for _ in range(rng.randint(2, 12)):
                goal = centre + sign * amplitude
                start = samples[-1][0] if samples and samples[-1][0] > 0 else centre
                for k in range(1, rng.randint(2, 8) + 1):
                    samples.append((start + (goal - start) * k / 8.0, load, h))
                samples.append((goal, load, h))
                history.append(goal)
                amplitude *= rng.uniform(0.5, 0.95)
                sign = -sign
        elif kind < 0.5 and history:            # back exactly to earlier levels
            for _ in range(rng.randint(1, 4)):
                samples += [(rng.choice(history), load, h)] * rng.randint(1, 3)
        elif kind < 0.6:                        # beyond either end (saturation), held
            level = rng.choice((hot - rng.uniform(0.0, 2.0), cold + rng.uniform(0.0, 2.0),
                                hot, cold, hot + 1e-9 * span, cold - 1e-9 * span))
            samples += [(level, load, h)] * rng.randint(1, 5)
        elif kind < 0.75:                       # a random ramp
            level = rng.uniform(hot - 0.5, cold + 0.5)
            start = samples[-1][0] if samples and samples[-1][0] > 0 else level
            n = rng.randint(3, 30)
            samples += [(start + (level - start) * k / n, load, h) for k in range(1, n + 1)]
        elif kind < 0.85:                       # a load change (sometimes past the limit)
            load = rng.choice([0.0, 0.02, 0.05, 0.1, 0.25, rng.uniform(0.0, 0.3),
                               params.load_max * rng.uniform(1.0, 1.6),
                               rng.choice([10.0, 100.0])])  # T_ref bounded to T_max there
        elif kind < 0.9:                        # a continuously varying load
            for _ in range(rng.randint(5, 40)):
                load = max(0.0, load + rng.gauss(0.0, 0.01))
                samples.append((rng.uniform(hot, cold), load, h))
        elif kind < 0.95:                       # another step size
            h = rng.choice([1e-3, 2e-3, 5e-4, 1e-2, rng.uniform(1e-5, 0.05)])
        else:                                   # noise around the last level
            last = samples[-1][0] if samples and samples[-1][0] > 0 else 0.5 * (hot + cold)
            samples += [(last + rng.gauss(0.0, 0.01 * span), load, h)
                        for _ in range(rng.randint(2, 20))]
    return samples[:steps]


def load_library(folder):
    """The runtime and the shim built into ``folder``, with the shim's signatures set."""
    return load_with_signatures(RUNTIME, folder, SHIM, SIGNATURES)
