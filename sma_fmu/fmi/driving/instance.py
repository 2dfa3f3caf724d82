"""One FMU instance driven through fmpy's ``FMU2Slave``, with variables by name.

Collects the FMU's log messages per instance and turns a failed FMI call into an
:class:`FmuError` that quotes them, so a discarded step says which input was wrong.
The stepping calls (set/get Real, get Boolean, doStep) go straight to the FMU's exported
C functions with preallocated arrays; everything else uses fmpy's wrappers. This class is
the FMI 2.0 adapter; :mod:`sma_fmu.fmi.driving.instance3` has the FMI 3.0 one. Instances of
the same FMU file share one unpacked folder per process (:mod:`sma_fmu.fmi.driving.unpacked`).
"""
import sys
from pathlib import Path
from ctypes import POINTER, PyDLL, byref, c_double, c_int, c_size_t, c_uint, c_void_p
from functools import partial
from itertools import count

from fmpy.fmi1 import FMICallException
from fmpy.logging import addLoggerProxy
from fmpy.fmi2 import (FMU2Slave, defaultCallbacks, fmi2CallbackFunctions,
                       fmi2CallbackLoggerTYPE)

from sma_fmu.console.interrupts import deferred
from sma_fmu.fmi.driving import unpacked

__all__ = ["FmuError", "FmuInstance"]

_STATUS = ["ok", "warning", "discard", "error", "fatal", "pending"]
# FMI passes a message as a printf format with arguments (the native family: "%s" and the
# text); ctypes cannot take C varargs, so fmpy's C proxy formats it. The proxy keeps one
# Python logger for the process: this permanent one hands each message to its instance,
# found by the componentEnvironment the instance gave.
_LOGGERS = {}
_KEYS = count(1)


def _dispatch(environment, instance_name, status, category, message):
    log = _LOGGERS.get(environment)
    if log is not None:
        log(environment, instance_name, status, category, message)


_DISPATCH = fmi2CallbackLoggerTYPE(_dispatch)


class FmuError(RuntimeError):
    """An FMI call failed; ``status`` is the FMI status, the message quotes the FMU's log."""

    def __init__(self, message, status):
        super().__init__(message)
        self.status = status


class Port:
    """A fixed tuple of variables with preallocated C arrays: the stepping hot path.

    ``set(values)`` / ``get()`` call the FMU's exported C function directly (fmpy's
    Python wrappers skipped) and raise :class:`FmuError` on a status above Warning.
    """

    def __init__(self, owner, names, references, ctype, setter, getter):
        self.owner = owner
        self.names = names
        self.count = len(references)
        self.references = (c_uint * self.count)(*references)
        self.values = (ctype * self.count)()
        self._setter = owner.bind(setter, self.references, self.values)
        self._getter = owner.bind(getter, self.references, self.values)

    def set(self, values):
        """Set the variables to ``values`` (same order as the names)."""
        self.values[:] = values
        status = self._setter()
        if status > 1:
            raise self.owner.failure(f"set {', '.join(self.names)}", status)

    def get(self):
        """The variables' values, as a list."""
        status = self._getter()
        if status > 1:
            raise self.owner.failure(f"get {', '.join(self.names)}", status)
        return self.values[:]


def _raw(library, name, argtypes):
    """The FMU's exported C function ``name`` with its types set (fmpy's own wrappers skipped)."""
    function = getattr(library, name)
    function.argtypes = argtypes
    function.restype = c_int
    return function


class FmuInstance:
    """Instantiate and initialize an FMU (co-simulation, FMI 2.0).

    The FMI 3.0 adapter, :class:`~sma_fmu.fmi.driving.instance3.Fmu3Instance`, is a subclass
    that overrides the version's calls (the methods under "FMI 2.0 calls" below);
    :func:`~sma_fmu.fmi.driving.instance3.open_instance` picks the class by the FMU's
    ``fmiVersion``.

    Parameters
    ----------
    path : str or Path
        The .fmu file.
    instance_name : str
    start_values : dict, optional
        Values set in initialization mode, by variable name (Real, Boolean or String
        parameters and inputs).
    start_time : float
        Start time [s].
    """

    PREFIX = "fmi2"  # of the FMI function names in messages
    # variable type -> (name of fmpy's setter, of the C set and get functions, the C type)
    ACCESSORS = {"Real": ("setReal", "fmi2SetReal", "fmi2GetReal", c_double),
                 "Integer": ("setInteger", "fmi2SetInteger", "fmi2GetInteger", c_int),
                 "Boolean": ("setBoolean", "fmi2SetBoolean", "fmi2GetBoolean", c_int),
                 "String": ("setString", "fmi2SetString", None, None)}
    PORT_TYPES = ("Real", "Boolean")  # what a Port (the hot path) takes
    # saved states: method -> (FMI function, fmpy's method)
    STATE_CALLS = {"get": ("fmi2GetFMUstate", "getFMUstate"), "set": ("fmi2SetFMUstate", "setFMUstate"),
                   "free": ("fmi2FreeFMUstate", "freeFMUstate"),
                   "serialize": ("fmi2SerializeFMUstate", "serializeFMUstate"),
                   "deserialize": ("fmi2DeSerializeFMUstate", "deSerializeFMUstate")}

    def __init__(self, path, instance_name, start_values=None, start_time=0.0):
        self.path = str(path)
        self.instance_name = instance_name
        # inspected before it is unpacked: never an archive that leaves its folder
        self._unpacked = unpacked.acquire(self.path)
        self._unzipped = self._unpacked.folder
        description = self._unpacked.description
        self.variables = {v.name: v for v in description.modelVariables}
        self.messages = []
        self._key = None
        try:
            self._fmu = self._slave(description)
        except BaseException as error:
            self._release()
            if "Cannot find shared library" in str(error):   # fmpy's words: no binary here
                from fmpy import platform
                raise FmuError(f"{self.path}: the FMU has no binary for this platform "
                               f"({platform}); build it here (sma-fmu build; with --native a "
                               f"compiler compiles its sources) or check it with sma-fmu check",
                               3) from None
            raise
        self._ports = {}
        self._reported = 0  # messages before this index are in an earlier FmuError already
        # the library fmpy loaded, called without releasing the GIL: pythonfmu's C++ takes it
        # back at once anyway (PyGILState_Ensure), so keeping it saves a hand-off per call
        library = PyDLL(self._fmu.dll._name, handle=self._fmu.dll._handle)
        self.library = library  # library["fmi2..."]: a function of its own (no argtypes set)
        self._raw = {}
        for kind in self.PORT_TYPES:
            _, set_name, get_name, ctype = self.ACCESSORS[kind]
            arguments = [c_void_p, POINTER(c_uint), c_size_t, POINTER(ctype)] + self._ARRAY_TAIL
            self._raw[kind] = (_raw(library, set_name, arguments), _raw(library, get_name, arguments),
                               ctype)
        self._do_step_c = self._raw_do_step(library)
        self.component = None
        self._alive = False
        try:
            with deferred():   # a Ctrl-C waits until the instance is made and known (freed below)
                self._instantiate()
                self._alive = True
            self.component = self._fmu.component
            self._enter_initialization(start_time)
            if start_values:
                self.set(start_values)
            seen = len(self.messages)
            try:
                self._call(f"{self.PREFIX}ExitInitializationMode", self._fmu.exitInitializationMode)
                failed = 0
            except FmuError as error:
                failed = error.status
            errors = [text for status, text in self.messages[seen:] if status in ("error", "fatal")]
            if failed or errors:  # (without the C front a refusal is only logged)
                raise FmuError(f"{instance_name}: initialization failed: {'; '.join(errors)}",
                               failed or 3)
            self._initialized()
        except BaseException:
            self.close()
            raise

    # ---- FMI 2.0 calls (Fmu3Instance overrides these) ----------------------------------------
    _ARRAY_TAIL = []  # C arguments of the set/get functions after the values (FMI 3: nValues)

    def _slave(self, description):
        """fmpy's slave object of the FMU (loads the library)."""
        return FMU2Slave(guid=description.guid, unzipDirectory=self._unzipped,
                         modelIdentifier=description.coSimulation.modelIdentifier,
                         instanceName=self.instance_name)

    def _raw_do_step(self, library):
        return _raw(library, "fmi2DoStep", [c_void_p, c_double, c_double, c_int])

    def _instantiate(self):
        self._callbacks = fmi2CallbackFunctions()
        self._key = next(_KEYS)
        _LOGGERS[self._key] = self._log
        self._callbacks.componentEnvironment = self._key
        self._callbacks.logger = _DISPATCH
        self._callbacks.allocateMemory = defaultCallbacks.allocateMemory
        self._callbacks.freeMemory = defaultCallbacks.freeMemory
        addLoggerProxy(byref(self._callbacks))  # formats; see _dispatch
        self._call("fmi2Instantiate", self._fmu.instantiate, callbacks=self._callbacks,
                   loggingOn=True)

    def _enter_initialization(self, start_time):
        self._call("fmi2SetupExperiment", self._fmu.setupExperiment, startTime=start_time)
        self._call("fmi2EnterInitializationMode", self._fmu.enterInitializationMode)

    def _initialized(self):
        """After fmi2ExitInitializationMode: nothing more in FMI 2.0."""

    def bind(self, function, references, values):
        """``function`` (a raw C set or get function) bound to this instance and the arrays
        ``references`` and ``values``: a call of no arguments returning the status."""
        return partial(function, c_void_p(self.component), references,
                       c_size_t(len(references)), values)

    def step_call(self):
        """The raw doStep bound to this instance: ``call(t, h, noSetFMUStatePriorToCurrentPoint)``
        returns the status."""
        return partial(self._do_step_c, c_void_p(self.component))

    def step(self, time, step_size):
        """doStep from ``time`` [s] over ``step_size`` [s]; raises FmuError unless fmi2OK/warning."""
        status = self._do_step_c(self.component, time, step_size, 1)
        if status > 1:
            raise self.failure("fmi2DoStep", status)

    def _terminate_and_free(self):
        try:
            self._fmu.terminate()
        except FMICallException:
            pass
        self._fmu.freeInstance()

    # ---- shared -------------------------------------------------------------------------------
    def _log(self, environment, instance_name, status, category, message):
        # the message as fmpy's proxy formatted it (_dispatch)
        self._record(status, message)

    def _record(self, status, message):
        """Keep one log message of the FMU (``message``: bytes)."""
        self.messages.append((_STATUS[status] if 0 <= status < len(_STATUS) else str(status),
                              (message or b"").decode("utf-8", "replace")))

    def _call(self, name, function, *args, **kwargs):
        """Call one of fmpy's wrappers; a failure becomes :class:`FmuError`."""
        self._reported = len(self.messages)
        try:
            return function(*args, **kwargs)
        except FMICallException as error:
            raise self.failure(name, error.status) from None
        except Exception as error:  # fmpy raises a bare Exception when instantiation fails
            raise self.failure(name, 4, str(error)) from None

    def port(self, names):
        """A :class:`Port` for the variables ``names`` (a tuple; all Real or all Boolean)."""
        names = tuple(names)
        port = self._ports.get(names)
        if port is None:
            try:
                variables = [self.variables[name] for name in names]
            except KeyError as error:
                raise KeyError(f"{self.instance_name}: no variable {error.args[0]!r} in "
                               f"{self.path}") from None
            kinds = {v.type for v in variables}
            if len(kinds) != 1 or not kinds <= set(self._raw):
                raise TypeError(f"{self.instance_name}: a port needs all-Real or all-Boolean "
                                f"variables, got {', '.join(sorted(kinds))}")
            setter, getter, ctype = self._raw[kinds.pop()]
            port = Port(self, names, [v.valueReference for v in variables], ctype, setter, getter)
            self._ports[names] = port
        return port

    def failure(self, what, status, fallback=None):
        """FmuError for a call that returned ``status``, quoting the FMU's new log lines."""
        seen, self._reported = self._reported, len(self.messages)
        log = "; ".join(text for _, text in self.messages[seen:]) or fallback or \
            f"{what} returned status {status}"
        if status == 4:  # Fatal: FMI allows no further call, not even FreeInstance
            self._alive = False
        return FmuError(f"{self.instance_name}: {what} failed ({_STATUS[status]}): {log}", status)

    def set(self, values):
        """Set variables by name: {name: value} (any type of :attr:`ACCESSORS`)."""
        groups = {kind: {} for kind in self.ACCESSORS}
        for name, value in values.items():
            variable = self.variables.get(name)
            if variable is None:
                raise KeyError(f"{self.instance_name}: no variable {name!r} in {self.path}")
            groups[variable.type][name] = value
        for kind, (method, function, _, _) in self.ACCESSORS.items():
            if groups[kind]:
                refs = [self.variables[n].valueReference for n in groups[kind]]
                self._call(function, getattr(self._fmu, method), refs, list(groups[kind].values()))

    def set_real(self, names, values):
        """Set Real variables ``names`` (a tuple) to ``values``."""
        self.port(names).set(values)

    def get_real(self, names):
        """Values of the Real variables ``names`` (a tuple)."""
        return self.port(names).get()

    def get_boolean(self, names):
        """Values of the Boolean variables ``names`` as bools."""
        return [value != 0 for value in self.port(names).get()]

    def _state_call(self, what, *args):
        function, method = self.STATE_CALLS[what]
        return self._call(function, getattr(self._fmu, method), *args)

    def get_state(self):
        """Save the FMU state (fmi2GetFMUstate); free it with :meth:`free_state`."""
        return self._state_call("get")

    def set_state(self, state):
        """Restore a state saved by :meth:`get_state` (fmi2SetFMUstate)."""
        self._state_call("set", state)

    def free_state(self, state):
        """Release a saved state (fmi2FreeFMUstate)."""
        self._state_call("free", state)

    def serialize_state(self, state):
        """Bytes of a saved state (fmi2SerializeFMUstate)."""
        return self._state_call("serialize", state)

    def deserialize_state(self, data):
        """A state from :meth:`serialize_state` bytes (fmi2DeSerializeFMUstate)."""
        return self._state_call("deserialize", data)

    def close(self):
        """Terminate and free the instance, and end its use of the unpacked folder.

        The folder stays for later instances of the same file (:mod:`sma_fmu.fmi.driving.unpacked`
        removes it at exit, or at its last use once the file has changed). pythonfmu puts the
        folder's ``resources`` on ``sys.path`` and leaves it there; it is taken off here,
        so a closed instance leaves no entry behind.
        """
        if self._alive:
            with deferred():   # freed whole: a Ctrl-C comes after
                self._alive = False
                self._terminate_and_free()
        _LOGGERS.pop(self._key, None)  # after the instance's last message
        resources = str(Path(self._unzipped) / "resources")
        sys.path[:] = [entry for entry in sys.path if entry.rstrip("/") != resources]
        self._release()

    def _release(self):
        """End this instance's use of the unpacked folder (once)."""
        if self._unpacked is not None:
            unpacked.release(self._unpacked)
            self._unpacked = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
