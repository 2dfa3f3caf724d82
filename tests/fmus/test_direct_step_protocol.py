"""The Python half of the front's direct fmi2DoStep (slave_support/direct_step.py).

The slave classes run in this process with a built FMU's resources and a buffer of doubles
as the front would give (attached the way the front attaches it); the direct step is then
called as the front calls it: step(t, h, inputs...). It returns the values the step changed
(the front copies them) or writes the buffer itself and returns whether the step was done.
The C half is tested through the built FMUs (test_fmu_direct_step.py).
"""
import ctypes
import importlib
import math

from sma_fmu.fmi.models import declaration
from sma_fmu.fmi.python_family.slave_support.fast_path import ATTACH, DESCRIBE, _CHANGING, _HEADER, _TIME, _WRITTEN

STEP = 1e-3


def _attached(unpacked, name, start=None):
    """(slave, buffer, direct step) of a slave in stepComplete with a front's buffer."""
    module = importlib.import_module(declaration(name).slave_module)
    slave = getattr(module, name)(instance_name="protocol", resources=str(unpacked[name] / "resources"))
    slave.setup_experiment(0.0, None, None)
    slave.enter_initialization_mode()
    for key, value in (start or {}).items():
        setattr(slave, key, value)
    slave.exit_initialization_mode()
    n = int(slave.get_string([DESCRIBE])[0].split()[1])
    buffer = (ctypes.c_double * (_HEADER + 2 * n))()
    slave.set_string([ATTACH], [f"{ctypes.addressof(buffer)} {n}"])
    fast = slave.interface.guard.fast
    assert fast.view is not None and fast._entry is not None
    return slave, buffer, fast._entry


def test_the_inlined_step_returns_the_stepper_outputs(unpacked):
    slave, buffer, step = _attached(unpacked, "SmaActuator", {"load": 0.05})
    assert buffer[_CHANGING] == len(slave.published) == 8
    outputs = step(0.0, STEP, 2.5, None)          # P_in set, load not
    assert isinstance(outputs, tuple) and slave.P_in == 2.5 and slave.load == 0.05
    assert list(outputs) == [getattr(slave, name) for name in slave.published]
    assert buffer[_TIME] == STEP == slave.interface.guard.time
    again = step(STEP, STEP, None, None)          # nothing new: P_in stays 2.5 W
    assert again.P == 2.5 and again.T > outputs.T  # heating on


def test_the_general_step_returns_the_changed_values(unpacked):
    slave, buffer, step = _attached(unpacked, "SmaPwmDriver")
    assert type(slave).declared_step is None
    values = step(0.0, STEP, 1e9, None)           # P_demand far above the peak: duty 1; R not set
    assert isinstance(values, tuple) and len(values) == int(buffer[_CHANGING])
    assert slave.P_in == slave.peak_W and slave.P_in in values
    assert buffer[_TIME] == STEP


def test_a_discarded_step_writes_the_buffer_and_says_not_done(unpacked):
    slave, buffer, step = _attached(unpacked, "SmaActuator")
    buffer[_WRITTEN] = 0.0
    assert step(0.0, STEP, math.nan, None) is False
    assert buffer[_WRITTEN] == 1.0 and slave.interface.guard.time == 0.0  # not advanced
    assert any("discarded" in text and "P_in" in text for text in _messages(slave))


def test_a_non_finite_output_puts_the_instance_in_the_error_state(unpacked):
    slave, buffer, step = _attached(unpacked, "SmaFeedforward")
    real_step = slave.stepper.step

    class Broken:  # a stepper whose output overflows (the guard must catch it)
        warning = None

        def step(self, *args):
            return (math.inf,) + tuple(real_step(*args))[1:]
    slave.stepper = Broken()
    assert step(0.0, STEP, None, None) is False
    assert slave.interface.guard.state == "error"
    assert any("non-finite output" in text for text in _messages(slave))


def test_outputs_that_are_no_tuple_are_not_handed_back_as_values(unpacked):
    """A stepper returning a list: the step is done, but the front gets no tuple and so
    treats its buffer as stale (it asks for every value before serving a call)."""
    slave, buffer, step = _attached(unpacked, "SmaPiController")
    stepper = slave.stepper

    class Listing:
        warning = None

        def sample(self, *args):
            return list(stepper.sample(*args))
    slave.stepper = Listing()
    result = step(0.0, STEP, 40.0, 41.0, 0.5)
    assert isinstance(result, list) and result and slave.interface.guard.time == STEP


def _messages(slave):
    """The texts pythonfmu queued for the logger."""
    return [entry.msg for entry in slave.log_queue]
