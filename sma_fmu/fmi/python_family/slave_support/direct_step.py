"""fmi2DoStep as the C front calls it when its checks passed (``fmi/python_family/front/fast_path.c``).

The front calls ``step(t, h, *inputs)``: t [s] and h [s] of the call, then one argument per
input settable in stepComplete, in slot order (:mod:`.fast_path`): the value the host set
since the last step, or None. The step returns either

- a tuple of the values the step changed, in slot order (the changing slots; the front
  copies them into its buffer, after the step wrote the guard's time there): the usual case,
  the slave is in stepComplete and its time is a float; or
- True / False (done or not) after writing the buffer itself: everything else (a discarded
  or refused step, an error state, values that are no numbers).

Two forms, compiled once per layout from the variable names (:mod:`.compiled`), each a
closure over as few objects as possible (every object a closure keeps is cyclic garbage
when the instance goes; the allocator kept about 4.5 KiB per instance when it held eight):

- general: the inputs, the guard's :meth:`~.guards.CallGuard.advance`, the changed values;
- inlined, for a :class:`~.stepper_slave.StepperSlave` that declares ``published`` and
  ``step_inputs`` and whose changing slots are exactly ``published``, in order: the
  slave's own do_step and the guard's advance written out (snap the step, call the stepper,
  publish), and the stepper's output tuple returned as it is (a stepper that returns no
  tuple leaves the front's buffer stale: it asks for every value before it serves a call
  again). Anything unusual (an
  exception, a non-finite or non-numeric output) takes the guard's own methods
  (``discarded``, ``stepped``), so messages and states are those of the general form.

None (no direct step: the front takes pythonfmu's DoStep) when a name is not an identifier.
"""
from pythonfmu.enums import Fmi2Status

from .compiled import compile_function, identifiers
from .lifecycle import STEP_COMPLETE

__all__ = ["direct_step"]

_GENERAL = '''
def make(view, guard, slave, fast):
    def step(t, h{parameters}):
        try:
{take}            done = guard.advance(t, h)
        except Exception as error:
            done = guard.internal("fmi2DoStep", error, False)
        if done and guard.state is STEP_COMPLETE:
            try:
                time = guard.time
                if time.__class__ is float:
                    changed = ({changed})
                    view[{time_slot}] = time
                    return changed
            except Exception:
                pass
        return fast.finish(done)
    return step
'''

_INLINED = '''
def make(view, guard, slave, interface, fast):
    def step(t, h{parameters}):
        try:
{take}        except Exception as error:
            return fast.finish(guard.internal("fmi2DoStep", error, False))
        try:
{snap}            stepper = slave.stepper
            outputs = stepper.{method}({arguments}step)
            {targets}, = outputs
        except Exception as error:
            return fast.finish(guard.discarded(t, error))
        try:
            total = sum(outputs)
            if total - total == 0.0:
                warning = stepper.warning
                guard.time = time = t + h
                if warning:
                    guard.log(WARNING, "fmi2DoStep", warning)
                view[{time_slot}] = time
                return outputs
        except Exception:
            pass
        return fast.finish(guard.stepped(t, h))
    return step
'''


def direct_step(fast, time_slot):
    """The direct step of ``fast`` (an attached :class:`~.fast_path.FastPath`), or None.
    ``time_slot``: the header slot of the guard's time."""
    guard, slave = fast.guard, fast.guard.slave
    inputs = [name for _, _, name, _ in fast._inputs]
    changing = list(fast._changing_names)
    declared = getattr(type(slave), "declared_step", None)
    if not identifiers(inputs + changing):
        return None
    parameters = "".join(f", input_{i}" for i in range(len(inputs)))
    take = "".join(f"            if input_{i} is not None:\n                slave.{name} = input_{i}\n"
                   for i, name in enumerate(inputs))
    scope = {"STEP_COMPLETE": STEP_COMPLETE, "WARNING": Fmi2Status.warning}
    if declared is not None and list(declared[2]) == changing and identifiers(declared[1]):
        method, arguments, published, snaps = declared
        snap = ("            step = h if h == interface.first_step else interface.nominal_step(h)\n"
                if snaps else "            step = h\n")
        source = _INLINED.format(
            parameters=parameters, take=take or "            pass\n", snap=snap, method=method,
            arguments="".join(f"slave.{name}, " for name in arguments),
            targets=", ".join(f"slave.{name}" for name in published), time_slot=time_slot)
        make = compile_function(source, "make", scope, "<fast path step, inlined>")
        return make(fast.view, guard, slave, guard.interface, fast)
    source = _GENERAL.format(parameters=parameters, take=take,
                             changed="".join(f"slave.{name}, " for name in changing),
                             time_slot=time_slot)
    make = compile_function(source, "make", scope, "<fast path step>")
    return make(fast.view, guard, slave, fast)
