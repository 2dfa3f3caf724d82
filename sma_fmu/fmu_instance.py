"""One FMU instance driven through fmpy's ``FMU2Slave``, with variables by name.

Collects the FMU's log messages per instance and turns a failed FMI call into an
:class:`FmuError` that quotes them, so a discarded step says which input was wrong.
"""
import shutil
from ctypes import byref

from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (FMU2Slave, defaultCallbacks, fmi2CallbackFunctions,
                       fmi2CallbackLoggerTYPE, fmi2Real, fmi2ValueReference)

__all__ = ["FmuError", "FmuInstance"]

_STATUS = ["ok", "warning", "discard", "error", "fatal", "pending"]


class FmuError(RuntimeError):
    """An FMI call failed; ``status`` is the FMI status, the message quotes the FMU's log."""

    def __init__(self, message, status):
        super().__init__(message)
        self.status = status


class FmuInstance:
    """Instantiate and initialize an FMU (co-simulation, FMI 2.0).

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

    def __init__(self, path, instance_name, start_values=None, start_time=0.0):
        self.path = str(path)
        self.instance_name = instance_name
        description = read_model_description(self.path)
        self.variables = {v.name: v for v in description.modelVariables}
        self.messages = []
        self._unzipped = extract(self.path)
        self._fmu = FMU2Slave(guid=description.guid, unzipDirectory=self._unzipped,
                              modelIdentifier=description.coSimulation.modelIdentifier,
                              instanceName=instance_name)
        self._callbacks = fmi2CallbackFunctions()
        self._logger = fmi2CallbackLoggerTYPE(self._log)
        self._callbacks.logger = self._logger
        self._callbacks.allocateMemory = defaultCallbacks.allocateMemory
        self._callbacks.freeMemory = defaultCallbacks.freeMemory
        try:
            from fmpy.logging import addLoggerProxy
            addLoggerProxy(byref(self._callbacks))
        except Exception:  # pragma: no cover - fmpy's optional native proxy is missing
            pass
        self._vr_cache = {}
        self._alive = False
        try:
            self._call("fmi2Instantiate", self._fmu.instantiate, callbacks=self._callbacks,
                       loggingOn=True)
            self._alive = True
            self._call("fmi2SetupExperiment", self._fmu.setupExperiment, startTime=start_time)
            self._call("fmi2EnterInitializationMode", self._fmu.enterInitializationMode)
            if start_values:
                self.set(start_values)
            seen = len(self.messages)
            self._call("fmi2ExitInitializationMode", self._fmu.exitInitializationMode)
            errors = [text for status, text in self.messages[seen:] if status in ("error", "fatal")]
            if errors:
                raise FmuError(f"{instance_name}: initialization failed: {'; '.join(errors)}", 3)
        except BaseException:
            self.close()
            raise

    def _log(self, environment, instance_name, status, category, message):
        self.messages.append((_STATUS[status] if 0 <= status < len(_STATUS) else str(status),
                              message.decode("utf-8", "replace")))

    def _call(self, name, function, *args, **kwargs):
        seen = len(self.messages)
        try:
            return function(*args, **kwargs)
        except FMICallException as error:
            status = error.status
        except Exception as error:  # fmpy raises a bare Exception when instantiation fails
            status, error = 4, error
        log = "; ".join(text for _, text in self.messages[seen:]) or str(error)
        if status == 4:  # fmi2Fatal: FMI allows no further call, not even fmi2FreeInstance
            self._alive = False
        raise FmuError(f"{self.instance_name}: {name} failed ({_STATUS[status]}): {log}", status)

    def _references(self, names):
        key = tuple(names)
        cached = self._vr_cache.get(key)
        if cached is None:
            try:
                refs = [self.variables[name].valueReference for name in names]
            except KeyError as error:
                raise KeyError(f"{self.instance_name}: no variable {error.args[0]!r} in "
                               f"{self.path}") from None
            cached = (fmi2ValueReference * len(refs))(*refs)
            self._vr_cache[key] = cached
        return cached

    def set(self, values):
        """Set variables by name: {name: value} (Real, Boolean or String)."""
        groups = {"Real": {}, "Boolean": {}, "String": {}}
        for name, value in values.items():
            variable = self.variables.get(name)
            if variable is None:
                raise KeyError(f"{self.instance_name}: no variable {name!r} in {self.path}")
            groups[variable.type][name] = value
        for kind, setter in (("Real", self._fmu.setReal), ("Boolean", self._fmu.setBoolean),
                             ("String", self._fmu.setString)):
            if groups[kind]:
                refs = [self.variables[n].valueReference for n in groups[kind]]
                self._call(f"fmi2Set{kind}", setter, refs, list(groups[kind].values()))

    def set_real(self, names, values):
        """Set Real variables ``names`` (a tuple, reused as a cache key) to ``values``."""
        refs = self._references(names)
        self._call("fmi2SetReal", self._fmu.fmi2SetReal, self._fmu.component, refs, len(refs),
                   (fmi2Real * len(refs))(*values))

    def get_real(self, names):
        """Values of the Real variables ``names`` (a tuple)."""
        refs = self._references(names)
        values = (fmi2Real * len(refs))()
        self._call("fmi2GetReal", self._fmu.fmi2GetReal, self._fmu.component, refs, len(refs),
                   values)
        return list(values)

    def get_boolean(self, names):
        """Values of the Boolean variables ``names`` as bools."""
        refs = [self.variables[name].valueReference for name in names]
        return [bool(v) for v in self._call("fmi2GetBoolean", self._fmu.getBoolean, refs)]

    def step(self, time, step_size):
        """doStep from ``time`` [s] over ``step_size`` [s]; raises FmuError unless fmi2OK/warning."""
        self._call("fmi2DoStep", self._fmu.doStep, time, step_size)

    def get_state(self):
        """Save the FMU state (fmi2GetFMUstate); free it with :meth:`free_state`."""
        return self._call("fmi2GetFMUstate", self._fmu.getFMUstate)

    def set_state(self, state):
        """Restore a state saved by :meth:`get_state` (fmi2SetFMUstate)."""
        self._call("fmi2SetFMUstate", self._fmu.setFMUstate, state)

    def free_state(self, state):
        """Release a saved state (fmi2FreeFMUstate)."""
        self._call("fmi2FreeFMUstate", self._fmu.freeFMUstate, state)

    def serialize_state(self, state):
        """Bytes of a saved state (fmi2SerializeFMUstate)."""
        return self._call("fmi2SerializeFMUstate", self._fmu.serializeFMUstate, state)

    def deserialize_state(self, data):
        """A state from :meth:`serialize_state` bytes (fmi2DeSerializeFMUstate)."""
        return self._call("fmi2DeSerializeFMUstate", self._fmu.deSerializeFMUstate, data)

    def close(self):
        """Terminate, free the instance and remove the unpacked FMU."""
        if self._alive:
            self._alive = False
            try:
                self._fmu.terminate()
            except FMICallException:
                pass
            self._fmu.freeInstance()
        shutil.rmtree(self._unzipped, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
