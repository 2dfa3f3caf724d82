"""ctypes wrappers of the C control blocks (c_family/runtime: pi_control, pwm, signals,
scenario_signals, json_text) for tests/native/test_c_runtime_control.py.

Each wrapper mirrors its Python class: the same calls, ``ValueError`` with the C message on a
refusal, and the saved state through the C state_write/state_read.
"""
import ctypes
import re

from c_runtime import compile_runtime

MODULES = ("pi_control", "pwm", "drive_limit", "signals", "scenario_signals", "json_text",
           "json_string", "json_number", "json_repr", "checks", "state_entries", "sma_message")

SHIM = r"""
#include <string.h>
#include "pi_control.h"
#include "pwm.h"
#include "scenario_signals.h"
size_t shim_size(int which)
{
    return which == 0 ? sizeof(PIController) : which == 1 ? sizeof(PwmDriver)
                                                          : sizeof(SignalSource);
}
int shim_source_new(const char *reference, const char *load, double start,
                    SignalSource *source, SmaMessage *message)
{
    ReferenceSignal r;
    LoadProfile l;
    if (signals_from_text(reference, load, &r, &l, message)) {
        return 1;
    }
    return signal_source_init(source, &r, &l, start, message);
}
int shim_parse(const char *text, char *repr, size_t size, char *error)
{
    JsonValue value;
    if (json_text_parse(text, &value, error, 512)) {
        return 1;
    }
    json_value_repr(&value, repr, size);
    json_value_free(&value);
    return 0;
}
"""

D = ctypes.c_double
P = ctypes.POINTER(ctypes.c_double)


def load_library(folder):
    lib = compile_runtime(MODULES, folder, extra_source=SHIM, name="control")
    lib.shim_size.restype = ctypes.c_size_t
    for name in ("pi_controller_state_size", "pwm_driver_state_size", "signal_source_state_size"):
        getattr(lib, name).restype = ctypes.c_size_t
    lib.pwm_driver_duty_of.restype = D
    lib.grid_time.restype = D
    return lib


class _Block:
    """An instance in ctypes memory with a message buffer and the state calls."""

    prefix = ""
    size_index = 0

    def __init__(self, lib):
        self.lib = lib
        self.memory = ctypes.create_string_buffer(lib.shim_size(self.size_index))
        self.message = ctypes.create_string_buffer(512)

    def call(self, name, *args):
        if getattr(self.lib, f"{self.prefix}_{name}")(self.memory, *args, self.message) != 0:
            raise ValueError(self.message.value.decode())

    def state(self):
        count = getattr(self.lib, f"{self.prefix}_state_size")(self.memory)
        out = (ctypes.c_double * count)()
        getattr(self.lib, f"{self.prefix}_state_write")(self.memory, out)
        return list(out)

    def restore(self, values):
        array = (ctypes.c_double * max(1, len(values)))(*values)
        self.call("state_read", array, ctypes.c_size_t(len(values)))


class CPIController(_Block):
    prefix = "pi_controller"
    size_index = 0

    def __init__(self, lib, Kp, Ki):
        super().__init__(lib)
        self.call("init", D(Kp), D(Ki))

    def sample(self, resistance, reference, feedforward, step_size):
        power, feedback = D(), D()
        self.call("sample", D(resistance), D(reference), D(feedforward), D(step_size),
                  ctypes.byref(power), ctypes.byref(feedback))
        return power.value, feedback.value

    def preview(self, resistance, reference, feedforward):
        power, feedback = D(), D()
        self.call("preview", D(resistance), D(reference), D(feedforward), ctypes.byref(power),
                  ctypes.byref(feedback))
        return power.value, feedback.value


class CPwmDriver(_Block):
    prefix = "pwm_driver"
    size_index = 1

    def __init__(self, lib, frequency_Hz, peak_W):
        super().__init__(lib)
        self.call("init", D(frequency_Hz), D(peak_W))

    def step(self, demand_W, time_s, step_size):
        power = D()
        self.call("step", D(demand_W), D(time_s), D(step_size), ctypes.byref(power))
        return power.value

    def held(self):
        """Python's held: None or (exact int index, duty), from the saved state."""
        base, minus_one, duty, _ = self.state()
        return None if base != base else (int(base) - int(minus_one), duty)


class CSignalSource(_Block):
    prefix = "signal_source"
    size_index = 2

    def __init__(self, lib, reference_text, load_text, start_time=0.0):
        super().__init__(lib)
        self.text = [None if t is None else t.encode("utf-8", "surrogatepass")
                     for t in (reference_text, load_text)]
        if lib.shim_source_new(self.text[0], self.text[1], D(start_time), self.memory,
                               self.message) != 0:
            self.memory = None
            raise ValueError(self.message.value.decode())

    def step(self, current_time, step_size):
        outputs = (ctypes.c_double * 2)()
        self.call("step", D(current_time), D(step_size), outputs)
        return outputs[0], outputs[1]

    def free(self):
        if self.memory is not None:
            self.lib.signal_source_free(self.memory)
            self.memory = None


def c_json(lib, text):
    """('OK', repr of the loaded value) or ('ERR', the decoder's message) from C."""
    repr_out, error = ctypes.create_string_buffer(65536), ctypes.create_string_buffer(512)
    if lib.shim_parse(text.encode("utf-8", "surrogatepass"), repr_out, ctypes.c_size_t(65536),
                      error):
        return "ERR", error.value.decode()
    return "OK", repr_out.value.decode("utf-8", "surrogatepass")


def c_number(lib, text):
    out = D()
    raw = text.encode()
    assert lib.json_number_value(raw, ctypes.c_size_t(len(raw)), ctypes.byref(out)) == 0, text
    return out.value


_NUMBER = re.compile(r"(?<![\w.])-?(?:\d+(?:\.\d*)?(?:e[-+]?\d+)?|inf|nan)(?![\w.])")


def normalized(message):
    """A message with every number as repr(float): C prints %.17g where Python prints repr."""
    return _NUMBER.sub(lambda m: repr(float(m.group())), message)
