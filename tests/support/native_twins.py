"""One FMU instance driven through fmpy's FMU2Slave, every call returning its FMI status, and
the host's log read through fmpy's C logger proxy (which formats the message with its
arguments, as a C host does): used side by side on a pythonfmu FMU and its native twin.

fmpy's proxy keeps one Python logger for the process: :data:`LOGS` routes its messages by
instance name, so the instance names of a test must differ.
"""
import random
import shutil
from ctypes import byref

from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, defaultCallbacks, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.logging import addLoggerProxy

__all__ = ["LOGS", "Driven", "Instance", "STATUS", "plant_walk", "compensator_walk"]

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


def _step_alike(sides, inputs, time, step):
    """Set ``inputs`` ({name: value}) on both ``sides``, step them from ``time`` [s] by
    ``step`` [s]; returns their outputs, asserted equal."""
    for side in sides:
        for name, value in inputs.items():
            side.set(name, value)
        assert side.step(time, step) <= 1, side.log[-2:]
    a, b = (side.values() for side in sides)
    assert a == b, (time, a, b)
    return a


def plant_walk(sides, library, seed, steps, load, load_rate=0.003, step=1e-3):
    """Drive the plant FMUs ``sides`` (a pythonfmu FMU and its native twin, started) and the
    library PlantStepper with random powers [W] and, at ``load_rate`` per step, random loads
    [kg] in [0, 0.4]: both families' outputs equal at every step, and R, T, x the library's."""
    rng, time, power = random.Random(seed), 0.0, 1.0
    for k in range(steps):
        if k % rng.randint(40, 300) == 0:
            power = rng.choice([0.0, rng.uniform(0.0, 4.0)])
        if rng.random() < load_rate:
            load = rng.uniform(0.0, 0.4)
        a = _step_alike(sides, {"P_in": power, "load": load}, time, step)
        time += step
        expected = library.step(power, load, step)
        assert (a["R"], a["T"], a["x"]) == (expected.R, expected.T, expected.x), k


def compensator_walk(sides, library, seed, steps, band, load, step=1e-3):
    """Drive the compensator FMUs ``sides`` and the library FeedforwardStepper with a
    reference [ohm] easing towards random targets in ``band`` at ``load`` [kg]: both
    families' outputs equal at every step, P_ff and T_ref the library's. Returns how many
    steps were not saturated."""
    rng, time, reference, target, inside = random.Random(seed), 0.0, band.cold, band.cold, 0
    for k in range(steps):
        if k % rng.randint(30, 250) == 0:
            target = rng.uniform(band.hot, band.cold)
        reference += 0.02 * (target - reference)
        a = _step_alike(sides, {"R_ref": reference}, time, step)
        time += step
        expected = library.step(reference, load, step)
        assert (a["P_ff"], a["T_ref"]) == (expected.P_ff, expected.T_ref), k
        inside += not expected.saturated
    return inside
