"""One FMU instance driven through fmpy's FMU2Slave, every call returning its FMI status, and
the host's log read through fmpy's C logger proxy (which formats the message with its
arguments, as a C host does): used side by side on a pythonfmu FMU and its native twin.

fmpy's proxy keeps one Python logger for the process: :data:`LOGS` routes its messages by
instance name, so the instance names of a test must differ.
"""
import shutil
from ctypes import byref

from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, defaultCallbacks, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.logging import addLoggerProxy

__all__ = ["LOGS", "Driven", "Instance", "STATUS"]

STATUS = {"ok": 0, "warning": 1, "discard": 2, "error": 3, "fatal": 4}
LOGS = {}  # instance name -> [(status, text)]


def _logger(environment, instance_name, status, category, message):
    LOGS.setdefault(instance_name.decode(), []).append((status, message.decode("utf-8", "replace")))


_LOGGER = fmi2CallbackLoggerTYPE(_logger)


class Driven:
    """What an instance of either FMI version shares (``fmu``: fmpy's FMU2Slave or FMU3Slave,
    ``outputs``, ``log``, ``folder``, ``get``): calls that return their status, outputs read,
    the end."""

    def call(self, method, *args, **kwargs):
        """(status, result) of a method of the fmpy slave."""
        try:
            return 0, getattr(self.fmu, method)(*args, **kwargs)
        except FMICallException as error:
            return error.status, None

    def values(self, names=None):
        """{name: value} of the outputs (or ``names``); every get must succeed."""
        found = {}
        for name in names or self.outputs:
            status, value = self.get(name)
            assert status <= 1, (self.name, name, self.log[-2:])
            found[name] = value
        return found

    def close(self):
        try:
            self.fmu.terminate()
        except FMICallException:
            pass
        self.fmu.freeInstance()
        shutil.rmtree(self.folder, ignore_errors=True)


class Instance(Driven):
    """An instantiated FMU (``path``) named ``name``; ``self.log`` holds its messages."""

    def __init__(self, path, name):
        description = read_model_description(str(path))
        self.variables = {v.name: v for v in description.modelVariables}
        self.outputs = [v.name for v in description.modelVariables if v.causality == "output"]
        self.folder = extract(str(path))
        self.name = name
        self.log = LOGS.setdefault(name.encode().decode(), [])
        self.log.clear()
        self.fmu = FMU2Slave(guid=description.guid, unzipDirectory=self.folder,
                             modelIdentifier=description.coSimulation.modelIdentifier,
                             instanceName=name)
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = _LOGGER
        self.callbacks.allocateMemory = defaultCallbacks.allocateMemory
        self.callbacks.freeMemory = defaultCallbacks.freeMemory
        addLoggerProxy(byref(self.callbacks))
        self.fmu.instantiate(callbacks=self.callbacks, loggingOn=False)

    def start(self, values=None, start_time=0.0):
        """setupExperiment, Initialization Mode with ``values`` set; status of exit."""
        self.fmu.setupExperiment(startTime=start_time)
        self.fmu.enterInitializationMode()
        for name, value in (values or {}).items():
            assert self.set(name, value) == 0, (name, value, self.log[-1:])
        return self.call("exitInitializationMode")[0]

    def set(self, name, value):
        variable = self.variables[name]
        method = "set" + variable.type
        return self.call(method, [variable.valueReference], [value])[0]

    def get(self, name):
        variable = self.variables[name]
        status, values = self.call("get" + variable.type, [variable.valueReference])
        return status, None if values is None else values[0]

    def step(self, time, step):
        """doStep's status (fmpy's doStep drops it: a warning would read as fmi2OK)."""
        try:
            return self.fmu.fmi2DoStep(self.fmu.component, time, step, 1)
        except FMICallException as error:
            return error.status

