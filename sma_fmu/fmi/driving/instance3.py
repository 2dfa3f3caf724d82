"""One FMI 3.0 co-simulation instance through fmpy's ``FMU3Slave``: the FMI 3.0 adapter of
:class:`~sma_fmu.fmi.driving.instance.FmuInstance`.

Only the version's calls differ; the log, the errors, the ports and the unpacked folder are
:class:`FmuInstance`'s. FMI 3.0's log callback gets the message as it is (no printf format)
and no instance name: each instance gets a callback of its own. Float64 stands for FMI 2.0's
Real, Int32 for Integer; the choices (``hysteresis_mode``, ``inverse``) are Enumerations,
read and set as Int64 with the codes of
:mod:`sma_fmu.fmi.python_family.slave_support.choices`.

With ``events=True`` the instance is made with ``eventModeUsed`` and ``earlyReturnAllowed``:
after initialization it is in Event Mode and :meth:`Fmu3Instance.handle_events` takes it to
Step Mode; :meth:`Fmu3Instance.step_events` reports what doStep said (an event to handle, an
early return and where the step ended). :func:`open_instance` picks the adapter by the FMU's
``fmiVersion``.
"""
from ctypes import addressof, c_bool, c_double, c_int32, c_int64, c_size_t, c_void_p
from functools import lru_cache, partial
from pathlib import Path

from fmpy.fmi3 import FMU3Slave

from sma_fmu.fmi.driving.description import read_description
from sma_fmu.fmi.driving.instance import FmuInstance, _raw

__all__ = ["Fmu3Instance", "open_instance", "fmi_major"]


def fmi_major(path):
    """The FMI major version of the FMU file ``path``: "2" or "3" (its model description's
    ``fmiVersion``; :class:`~sma_fmu.fmi.driving.description.FmuFileError` for no usable FMU).
    Read once per file version (path, size, modification time): masters ask on every run."""
    path = Path(path)
    if not path.is_file():
        read_description(path)  # raises the named error
    stat = path.stat()
    return _major((str(path.resolve()), stat.st_size, stat.st_mtime_ns))


@lru_cache(maxsize=64)
def _major(version):
    return read_description(version[0]).fmiVersion.split(".")[0]


def open_instance(path, instance_name, start_values=None, start_time=0.0, events=False):
    """An initialized instance of the FMU ``path``: :class:`FmuInstance` for FMI 2.0,
    :class:`Fmu3Instance` for FMI 3.0 (``events``: event mode and early return, FMI 3.0 only;
    ``ValueError`` naming the FMU for an FMI 2.0 one)."""
    if fmi_major(path) == "3":
        return Fmu3Instance(path, instance_name, start_values, start_time, events=events)
    if events:
        raise ValueError(f"{path} is an FMI 2.0 FMU: event mode and early return need FMI 3.0 "
                         f"FMUs (sma-fmu build --native --fmi 3)")
    return FmuInstance(path, instance_name, start_values, start_time)


class Fmu3Instance(FmuInstance):
    """Instantiate and initialize an FMI 3.0 co-simulation FMU (see :class:`FmuInstance`).

    ``events``: instantiate with ``eventModeUsed`` and ``earlyReturnAllowed``.
    """

    PREFIX = "fmi3"
    ACCESSORS = {"Float64": ("setFloat64", "fmi3SetFloat64", "fmi3GetFloat64", c_double),
                 "Int32": ("setInt32", "fmi3SetInt32", "fmi3GetInt32", c_int32),
                 "Enumeration": ("setInt64", "fmi3SetInt64", "fmi3GetInt64", c_int64),
                 "Boolean": ("setBoolean", "fmi3SetBoolean", "fmi3GetBoolean", c_bool),
                 "String": ("setString", "fmi3SetString", None, None)}
    PORT_TYPES = ("Float64", "Boolean")
    STATE_CALLS = {"get": ("fmi3GetFMUState", "getFMUState"), "set": ("fmi3SetFMUState", "setFMUState"),
                   "free": ("fmi3FreeFMUState", "freeFMUState"),
                   "serialize": ("fmi3SerializeFMUState", "serializeFMUState"),
                   "deserialize": ("fmi3DeserializeFMUState", "deserializeFMUState")}
    _ARRAY_TAIL = [c_size_t]  # nValues

    def __init__(self, path, instance_name, start_values=None, start_time=0.0, events=False):
        self.events = bool(events)
        # doStep's outputs: eventHandlingNeeded, terminateSimulation, earlyReturn, lastSuccessfulTime
        self.flags = (c_bool(), c_bool(), c_bool(), c_double())
        # their addresses as void* arguments: ctypes passes these faster than byref() objects
        self._flag_refs = tuple(c_void_p(addressof(flag)) for flag in self.flags)
        super().__init__(path, instance_name, start_values, start_time)

    def _slave(self, description):
        return FMU3Slave(guid=description.instantiationToken, unzipDirectory=self._unzipped,
                         modelIdentifier=description.coSimulation.modelIdentifier,
                         instanceName=self.instance_name)

    def _raw_do_step(self, library):
        return _raw(library, "fmi3DoStep", [c_void_p, c_double, c_double, c_bool] + [c_void_p] * 4)

    def _log3(self, environment, status, category, message):
        self._record(status, message)

    def _instantiate(self):
        self._call("fmi3InstantiateCoSimulation", self._fmu.instantiate, loggingOn=True,
                   eventModeUsed=self.events, earlyReturnAllowed=self.events,
                   logMessage=self._log3)

    def _enter_initialization(self, start_time):
        self._call("fmi3EnterInitializationMode", self._fmu.enterInitializationMode,
                   startTime=start_time)

    def _initialized(self):
        """With event mode the instance is in Event Mode now: to Step Mode."""
        if self.events:
            self.handle_events(entered=True)

    def bind(self, function, references, values):
        count = c_size_t(len(references))
        return partial(function, c_void_p(self.component), references, count, values, count)

    def step_call(self):
        """The raw fmi3DoStep bound to this instance and :attr:`flags`: ``call(t, h, noSet)``
        returns the status. With event mode, an event asked for is handled at once (the
        instance is back in Step Mode); an early return raises :class:`FmuError` (a block that
        may return early is stepped with :meth:`step_events`)."""
        raw, component = self._do_step_c, c_void_p(self.component)
        a, b, c, d = self._flag_refs
        if not self.events:
            return lambda time, step_size, no_set: raw(component, time, step_size, no_set, a, b, c, d)
        event, early = self.flags[0], self.flags[2]

        def call(time, step_size, no_set):
            status = raw(component, time, step_size, no_set, a, b, c, d)
            if status <= 1 and early.value:
                raise self.failure("fmi3DoStep", 3, f"returned early at t = {self.flags[3].value!r} "
                                   f"s, which this block's master does not handle")
            if status <= 1 and event.value:
                self.handle_events()
            return status
        return call

    def step(self, time, step_size):
        """doStep from ``time`` [s] over ``step_size`` [s]; raises FmuError unless fmi3OK/warning."""
        status = self._do_step_c(self.component, time, step_size, True, *self._flag_refs)
        if status > 1:
            raise self.failure("fmi3DoStep", status)

    def step_events(self, time, step_size):
        """doStep from ``time`` [s] over at most ``step_size`` [s]: (eventHandlingNeeded,
        earlyReturn, lastSuccessfulTime [s]); raises FmuError unless fmi3OK/warning or when
        the FMU asks to terminate."""
        self.step(time, step_size)
        event, terminate, early, last = (flag.value for flag in self.flags)
        if terminate:
            raise self.failure("fmi3DoStep", 3, f"terminateSimulation at t = {last!r} s")
        return event, early, last

    def handle_events(self, entered=False):
        """fmi3EnterEventMode (unless ``entered``), fmi3UpdateDiscreteStates until no discrete
        state needs an update, fmi3EnterStepMode; FmuError names the call that failed."""
        if not entered:
            self._call("fmi3EnterEventMode", self._fmu.enterEventMode)
        for _ in range(1000):  # choice: a model that never settles is an error, not a hang
            update = self._call("fmi3UpdateDiscreteStates", self._fmu.updateDiscreteStates)
            if update[1]:
                raise self.failure("fmi3UpdateDiscreteStates", 3, "terminateSimulation")
            if not update[0]:
                break
        else:
            raise self.failure("fmi3UpdateDiscreteStates", 3, "discrete states still need an "
                               "update after 1000 iterations")
        self._call("fmi3EnterStepMode", self._fmu.enterStepMode)
