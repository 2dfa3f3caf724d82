"""ctypes wrappers of the C bench hardware blocks (c_family/runtime: noise, measurement,
drive_limit, and pwm's limited step) for tests/native/test_c_runtime_hardware.py.

Each wrapper mirrors its Python class: the same calls, ``ValueError`` with the C message on a
refusal, the saved state through the C state_write/state_read.
"""
import ctypes

from c_control import _Block as _ControlBlock
from c_runtime import compile_runtime

MODULES = ("noise", "measurement", "pi_control", "drive_limit", "pwm", "checks",
           "state_entries", "sma_message")

SHIM = r"""
#include "drive_limit.h"
#include "measurement.h"
#include "pwm.h"
size_t shim_size(int which)
{
    return which == 0 ? sizeof(ResistanceSensor) : which == 1 ? sizeof(SensedPIController)
         : which == 2 ? sizeof(LinearDriver) : which == 3 ? sizeof(PwmDriver) : sizeof(DriveLimit);
}
int shim_sensed_pi_init(SensedPIController *c, double Kp, double Ki, double noise,
                        double full_scale, long bits, long seed, SmaMessage *message)
{
    return pi_controller_init(&c->pi, Kp, Ki, message)
        || resistance_sensor_init(&c->sensor, noise, full_scale, bits, seed, message);
}
int shim_linear_init(LinearDriver *d, double I, double V, SmaMessage *message)
{
    DriveLimit limit;
    if (drive_limit_init(&limit, I, V, message)) return 1;
    linear_driver_init(d, &limit);
    return 0;
}
int shim_pwm_init(PwmDriver *d, double f, double peak, double I, double V, SmaMessage *message)
{
    DriveLimit limit;
    if (drive_limit_init(&limit, I, V, message) || pwm_driver_init(d, f, peak, message)) return 1;
    pwm_driver_set_limit(d, &limit);
    return 0;
}
"""

D = ctypes.c_double
U64 = ctypes.c_uint64
P = ctypes.POINTER(ctypes.c_double)


def load_library(folder):
    lib = compile_runtime(MODULES, folder, extra_source=SHIM, name="hardware")
    lib.shim_size.restype = ctypes.c_size_t
    lib.standard_normal.restype, lib.standard_normal.argtypes = D, (U64, U64)
    lib.splitmix64_word.restype, lib.splitmix64_word.argtypes = U64, (U64, U64)
    lib.resistance_sensor_reading.restype = D
    lib.resistance_sensor_reading.argtypes = (ctypes.c_void_p, D, U64)
    lib.drive_limit_cap.restype, lib.drive_limit_apply.restype = D, D
    for name in ("resistance_sensor_state_size", "sensed_pi_state_size",
                 "linear_driver_state_size", "pwm_driver_state_size"):
        getattr(lib, name).restype = ctypes.c_size_t
    return lib


class _Block(_ControlBlock):
    """c_control's block (memory, message, call, state, restore) with ``check`` for the
    shims' status."""

    def check(self, status):
        if status != 0:
            raise ValueError(self.message.value.decode())


class CSensor(_Block):
    prefix = "resistance_sensor"
    size_index = 0

    def __init__(self, lib, noise, full_scale, bits, seed):
        super().__init__(lib)
        self.call("init", D(noise), D(full_scale), ctypes.c_long(bits), ctypes.c_long(seed))

    def reading(self, resistance, sample):
        return self.lib.resistance_sensor_reading(self.memory, resistance, sample)

    def measure(self, resistance):
        out = D()
        self.call("measure", D(resistance), ctypes.byref(out))
        return out.value

    def preview(self, resistance):
        out = D()
        self.call("preview", D(resistance), ctypes.byref(out))
        return out.value


class CSensedPI(_Block):
    prefix = "sensed_pi"
    size_index = 1

    def __init__(self, lib, Kp, Ki, noise, full_scale, bits, seed):
        super().__init__(lib)
        self.check(lib.shim_sensed_pi_init(self.memory, D(Kp), D(Ki), D(noise), D(full_scale),
                                           ctypes.c_long(bits), ctypes.c_long(seed), self.message))

    def sample(self, resistance, reference, feedforward, step_size):
        power, feedback, measured = D(), D(), D()
        self.call("sample", D(resistance), D(reference), D(feedforward), D(step_size),
                  ctypes.byref(power), ctypes.byref(feedback), ctypes.byref(measured))
        return power.value, feedback.value, measured.value

    def preview(self, resistance, reference, feedforward):
        power, feedback, measured = D(), D(), D()
        self.call("preview", D(resistance), D(reference), D(feedforward), ctypes.byref(power),
                  ctypes.byref(feedback), ctypes.byref(measured))
        return power.value, feedback.value, measured.value


class CLinearDriver(_Block):
    prefix = "linear_driver"
    size_index = 2

    def __init__(self, lib, I_max, V_max):
        super().__init__(lib)
        self.check(lib.shim_linear_init(self.memory, D(I_max), D(V_max), self.message))

    def step(self, demand, time_s, step_size, resistance):
        power = D()
        self.call("step", D(demand), D(time_s), D(step_size), D(resistance), ctypes.byref(power))
        return power.value


class CLimitedPwm(_Block):
    prefix = "pwm_driver"
    size_index = 3

    def __init__(self, lib, frequency, peak, I_max, V_max):
        super().__init__(lib)
        self.check(lib.shim_pwm_init(self.memory, D(frequency), D(peak), D(I_max), D(V_max),
                                     self.message))

    def step(self, demand, time_s, step_size, resistance):
        power = D()
        self.call("step_limited", D(demand), D(time_s), D(step_size), D(resistance),
                  ctypes.byref(power))
        return power.value


class CLimit(_Block):
    size_index = 4

    def __init__(self, lib, I_max, V_max):
        super().__init__(lib)
        self.check(lib.drive_limit_init(self.memory, D(I_max), D(V_max), self.message))

    def cap(self, resistance):
        return self.lib.drive_limit_cap(self.memory, D(resistance))

    def apply(self, power, resistance):
        return self.lib.drive_limit_apply(self.memory, D(power), D(resistance))
