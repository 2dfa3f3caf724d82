"""One FMI 3.0 instance driven through fmpy's FMU3Slave, every call returning its FMI status,
with the same interface as native_twins.Instance (FMI 2.0; both are native_twins.Driven), so
the two versions of a C-family FMU can be driven side by side. Each instance has its own
logger (FMI 3.0 passes no instance name to it); Enumerations are read and set as Int64;
structural parameters (the plant's memory_depth) are set in Configuration Mode.
"""
from ctypes import byref

from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi3 import FMU3Slave, fmi3Boolean, fmi3Float64

from native_twins import Driven

__all__ = ["Instance3"]

_ACCESSOR = {"Enumeration": "Int64"}


class Instance3(Driven):
    """An instantiated FMI 3.0 FMU (``path``) named ``name``; ``self.log``: its messages."""

    def __init__(self, path, name, event_mode=False, early_return=False):
        description = read_model_description(str(path))
        self.variables = {v.name: v for v in description.modelVariables}
        outputs = [v for v in description.modelVariables if v.causality == "output"]
        self.outputs = [v.name for v in outputs if not v.dimensions]  # scalars
        self.arrays = [v.name for v in outputs if v.dimensions]        # read by array()
        self.folder = extract(str(path))
        self.name = name
        self.log = []
        self.fmu = FMU3Slave(guid=description.instantiationToken, unzipDirectory=self.folder,
                             modelIdentifier=description.coSimulation.modelIdentifier,
                             instanceName=name)
        self.fmu.instantiate(loggingOn=False, eventModeUsed=event_mode,
                             earlyReturnAllowed=early_return, logMessage=self._logger)

    def _logger(self, environment, status, category, message):
        self.log.append((status, message.decode("utf-8", "replace")))

    def configure(self, values):
        """Configuration Mode with the structural parameters of ``values`` set (FMI 3.0 sets
        them there alone); the others of ``values``."""
        structural = {n: v for n, v in values.items()
                      if self.variables[n].causality == "structuralParameter"}
        if structural:
            self.fmu.enterConfigurationMode()
            for name, value in structural.items():
                assert self.set(name, value) == 0, (name, value, self.log[-1:])
            self.fmu.exitConfigurationMode()
        return {n: v for n, v in values.items() if n not in structural}

    def start(self, values=None, start_time=0.0):
        """Initialization Mode with ``values`` set (structural parameters in Configuration
        Mode before it); the status of its exit."""
        values = self.configure(values or {})
        self.fmu.enterInitializationMode(startTime=start_time)
        for name, value in values.items():
            assert self.set(name, value) == 0, (name, value, self.log[-1:])
        return self.call("exitInitializationMode")[0]

    def _type(self, name):
        kind = self.variables[name].type
        return _ACCESSOR.get(kind, kind)

    def set(self, name, value):
        return self.call("set" + self._type(name), [self.variables[name].valueReference], [value])[0]

    def get(self, name):
        status, values = self.call("get" + self._type(name), [self.variables[name].valueReference])
        return status, None if values is None else values[0]

    def array(self, name, size=None):
        """(status, list) of an array output, ``size`` values (default: its dimension's
        structural parameter as the FMU reports it)."""
        variable = self.variables[name]
        if size is None:
            size = 1
            for dimension in variable.dimensions:
                status, length = self.get(dimension.variable.name)
                assert status == 0, self.log[-1:]
                size *= length
        return self.call("getFloat64", [variable.valueReference], nValues=size)

    def do_step(self, time, step):
        """(status, eventHandlingNeeded, terminateSimulation, earlyReturn, lastSuccessfulTime)."""
        flags = [fmi3Boolean(), fmi3Boolean(), fmi3Boolean()]
        last = fmi3Float64()
        try:
            status = self.fmu.fmi3DoStep(self.fmu.component, time, step, fmi3Boolean(True),
                                         *(byref(f) for f in flags), byref(last))
        except FMICallException as error:
            status = error.status
        return (status, *(bool(f.value) for f in flags), last.value)

    def step(self, time, step):
        return self.do_step(time, step)[0]
