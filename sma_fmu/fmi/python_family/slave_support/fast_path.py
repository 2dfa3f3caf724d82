"""The slave's side of the C front's fast path (``fmi/python_family/front/fast_path.c``).

In stepComplete the front serves fmi2Set/GetReal, Integer and Boolean from a buffer of
doubles it holds; Python runs only in fmi2DoStep (and in the calls that need the model).
The slave writes its state and values into that buffer; the front writes the inputs it
accepted there and marks them pending; the slave takes them at the next step, or when the
front asks (before any other call reaches the slave).

The front talks to the slave through three value references no variable has, each used
only as the only reference of a call:

- fmi2GetString(``DESCRIBE``): the variable table, ``"SMAFAST1 <n> (<kind> <vr> <settable>)*n"``
  (kind R, I or B; settable: 1 if the variable may be set in stepComplete, as the guard's
  tables say). Answered until the buffer is attached.
- fmi2SetString(``ATTACH``, ``"<address> <n>"``): the buffer. The slave writes every value.
- fmi2GetString(``SYNC``): take the pending inputs, write every value. Answered only when the
  front has set the buffer's request flag, so a host calling with it is refused as before.
- fmi2GetString(``LOG``): nothing (answered only when the front asked); pythonfmu passes the
  messages queued by a direct step (below) to the logger at the end of this call.

fmi2DoStep: the front makes the guard's model-free checks in C (stepComplete, finite t and
h > 0, t follows the last step, stopTime; from the time, stopTime and state the slave writes
into the header) and, when they pass, calls the slave's direct step itself through Python's
C API (:mod:`.direct_step`; its address is in the header) with t, h and the pending inputs as
arguments: no pythonfmu DoStep, no log-queue crossing unless a message was queued. The step
returns the values it changed (the front copies them) or writes the buffer itself.
Otherwise the call takes pythonfmu's DoStep and the guard refuses it with its message, as
before.

Slot order: the variables a step changes (outputs, locals) first, then inputs and parameters.
Buffer: header (``_HEADER`` doubles: stepComplete, written, pending, sync request, write all
at the next step; the guard's stopTime (NaN: None) and whether C may check it and the time;
the log request, the addresses of the direct step (0: none) and of pythonfmu's log queue,
the number of slots a step changes; last the guard's time (NaN: None), so that it and the
values a step changes are written in one pack), the n values, the n pending flags. Without
the front (or with ``SMA_FMU_NO_FAST_PATH=1``) nothing is attached and every call takes the
guard's path.
"""
import ctypes
import struct

from .compiled import attribute_reader
from .direct_step import direct_step
from .lifecycle import INSTANTIATED, STEP_COMPLETE

__all__ = ["FastPath", "DESCRIBE", "ATTACH", "SYNC", "LOG", "PENDING"]

DESCRIBE, ATTACH, SYNC, LOG = 0xFFFFFA51, 0xFFFFFA52, 0xFFFFFA53, 0xFFFFFA54
_HEADER = 12  # as FAST_HEADER in fmi/python_family/front/front.h
(_STEP_COMPLETE, _WRITTEN, PENDING, _SYNC, _FULL,  # PENDING: inputs set in C since the last step
 _STOP, _CHECKABLE, _LOG, _ENTRY, _QUEUE, _CHANGING, _TIME) = range(_HEADER)  # _TIME: next to the values
_NAN = float("nan")
_KINDS = (("Real", "R", float), ("Integer", "I", int), ("Boolean", "B", bool))


def _as_double(kind):
    if kind == "B":
        return lambda value: 1.0 if value else 0.0
    if kind == "I":
        return lambda value: float(int(value))
    return float


class FastPath:
    """The buffer one slave shares with the front (see the module docstring)."""

    def __init__(self, guard):
        self.guard = guard
        self.view = None  # memoryview of doubles once attached
        self.slots = None

    def reference(self, references):
        """The fast-path reference of a one-reference call (unsigned), or None."""
        if len(references) != 1:
            return None
        reference = references[0] & 0xFFFFFFFF
        return reference if reference in (DESCRIBE, ATTACH, SYNC, LOG) else None

    # ---- the table -------------------------------------------------------------------------
    def _table(self):
        """(slots, number of slots a step changes): those first, the Real outputs leading in
        the guard's order (:meth:`~.guards.CallGuard.outputs_finite`)."""
        interface = self.guard.interface
        outputs = {name: i for i, name in enumerate(interface.real_output_names())}
        changing, fixed = [], []
        for kind, code, convert in _KINDS:
            names = interface.names(kind)
            settable = interface.settable(kind, STEP_COMPLETE)
            free = interface.settable(kind, INSTANTIATED)  # inputs and parameters
            for reference, name in sorted(names.items()):
                entry = (code, reference, name, reference in settable, convert)
                (fixed if reference in free else changing).append(entry)
        changing.sort(key=lambda e: (e[0] != "R" or e[2] not in outputs, outputs.get(e[2], 0)))
        return changing + fixed, len(changing)

    def describe(self):
        """fmi2GetString(DESCRIBE): the table text ("" once attached)."""
        if self.view is not None:
            return ""
        slots, _ = self._table()
        return f"SMAFAST1 {len(slots)} " + " ".join(
            f"{code} {reference} {int(settable)}" for code, reference, _, settable, _ in slots)

    def attach(self, text):
        """fmi2SetString(ATTACH, "<address> <n>"): use the front's buffer; write every value."""
        if self.view is not None:
            return
        address, count = (int(word) for word in text.split())
        slots, n_changing = self._table()
        if count != len(slots):
            return
        array = (ctypes.c_double * (_HEADER + 2 * count)).from_address(address)
        self.view = memoryview(array).cast("B").cast("d")
        self.slots = slots
        self._names = [name for _, _, name, _, _ in slots]
        self._to_double = [_as_double(code) for code, _, _, _, _ in slots]
        # the inputs settable in stepComplete: (value index, pending index, name, convert)
        self._inputs = [(_HEADER + i, _HEADER + count + i, name, convert)
                        for i, (_, _, name, settable, convert) in enumerate(slots) if settable]
        # after a step: the time and the values a step changes, in one pack (struct's "d"
        # reads a Boolean or Integer as the front does: v != 0, (int)v)
        self._changing_names = self._names[:n_changing]
        self._changing = attribute_reader(self._changing_names)
        self._changing_struct = struct.Struct(f"{1 + n_changing}d")
        self._raw = memoryview(array).cast("B")
        self._log_queue = self.guard.slave._get_log_queue()  # pythonfmu's list (it empties it)
        # kept alive with the slave: the front holds its address
        self._entry = direct_step(self, _TIME)
        self.write_all()
        self.view[_QUEUE] = float(id(self._log_queue))
        self.view[_CHANGING] = float(n_changing)
        self.view[_ENTRY] = 0.0 if self._entry is None else float(id(self._entry))

    # ---- values ------------------------------------------------------------------------------
    def take_inputs(self):
        """Set the inputs the front marked pending (stepComplete: it checked them)."""
        view, slave = self.view, self.guard.slave
        for value, pending, name, convert in self._inputs:
            if view[pending]:
                setattr(slave, name, convert(view[value]))
                view[pending] = 0.0
        view[PENDING] = 0.0

    def write_all(self):
        """Every value and the state into the buffer (a value that is no number: the fast
        path is off until the next write)."""
        view, slave = self.view, self.guard.slave
        try:
            for index, (name, to_double) in enumerate(zip(self._names, self._to_double)):
                view[_HEADER + index] = to_double(getattr(slave, name))
            view[_STEP_COMPLETE] = 1.0 if self.guard.state is STEP_COMPLETE else 0.0
            self._write_times()
        except Exception:  # noqa: BLE001 - then every call goes to the guard
            view[_STEP_COMPLETE] = 0.0
        view[_WRITTEN] = 1.0

    def _write_times(self):
        """The guard's time and stopTime for the front's doStep checks (NaN: None); C checks
        them only when both are floats or None (a restored state may hold an int)."""
        view, guard = self.view, self.guard
        time, stop = guard.time, guard.stop_time
        checkable = (time is None or time.__class__ is float) and \
            (stop is None or stop.__class__ is float)
        view[_CHECKABLE] = 1.0 if checkable else 0.0
        if checkable:
            view[_TIME] = _NAN if time is None else time
            view[_STOP] = _NAN if stop is None else stop

    def write_step(self):
        """After fmi2DoStep: the time, the values a step changes and the state; every value
        if the front asked."""
        view = self.view
        if view[_FULL]:
            view[_FULL] = 0.0
            return self.write_all()
        self.write_changed()

    def finish(self, result):
        """:meth:`write_changed`, then ``result`` (the direct step's unusual cases)."""
        self.write_changed()
        return result

    def write_changed(self):
        """The time, the values a step changes (one pack) and the state."""
        view, guard = self.view, self.guard
        try:
            time = guard.time
            self._changing_struct.pack_into(self._raw, 8 * _TIME, _NAN if time is None else time,
                                            *self._changing(guard.slave))
            view[_STEP_COMPLETE] = 1.0 if guard.state is STEP_COMPLETE else 0.0
            if time.__class__ is not float or not view[_CHECKABLE]:
                self._write_times()
        except Exception:  # noqa: BLE001 - then every call goes to the guard
            view[_STEP_COMPLETE] = 0.0
        view[_WRITTEN] = 1.0

    def sync(self, reference):
        """fmi2GetString(SYNC) from the front: take the pending inputs, write every value;
        fmi2GetString(LOG): nothing (pythonfmu passes the queued messages on after it).
        False if the front did not ask (a host's call: refused as an unknown reference)."""
        view = self.view
        if view is None:
            return False
        if reference == LOG:
            if not view[_LOG]:
                return False
            view[_LOG] = 0.0
            return True
        if reference != SYNC or not view[_SYNC]:
            return False
        view[_SYNC] = 0.0
        if view[PENDING]:
            self.take_inputs()
        self.write_all()
        return True

