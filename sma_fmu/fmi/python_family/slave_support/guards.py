"""Guards around every pythonfmu callback of a slave: the FMI state machine, checked
arguments, and no exception ever escaping to pythonfmu.

pythonfmu 0.7.0 turns any Python exception in a callback into fmi2Fatal and then frees
the instance's Python objects (a later call or fmi2FreeInstance crashes the host).
Python callbacks cannot return an FMI status either (only ``do_step``'s bool becomes
fmi2OK or fmi2Discard). So a refused call is *logged* with status fmi2Error (or
fmi2Warning, fmi2Discard) and has no effect; sma-fmu's C front (``fmi/python_family/front/``)
returns the worst status the slave logged during a call as that call's status. Without
the front (an FMU built where no C compiler was found) the message is the only signal:
the call still returns fmi2OK (doStep: fmi2Discard). See docs/fmus.md.

With the front, fmi2Set/Get in stepComplete never reach Python: the front serves them from
values it holds, with the same rules, and passes everything it would refuse on to the guard
(:mod:`.fast_path`). fmi2DoStep takes the inputs from it and gives the outputs back.

:class:`CallGuard` installs itself over the slave's callbacks (instance attributes shadow
the class's methods, so a slave written in the usual style gets it by creating its
:class:`~.interface.SlaveInterface`).
"""
import math

from pythonfmu.enums import Fmi2Status

from .compiled import attribute_reader
from .fast_path import ATTACH, DESCRIBE, PENDING, FastPath
from .lifecycle import ALLOWED, ERROR, INITIALIZATION, INSTANTIATED, STEP_COMPLETE, TERMINATED
from .refusal_text import shown_value, unknown_references
from .saved_state import SavedStates

__all__ = ["CallGuard"]

_INF = float("inf")
_NAN = float("nan")


def _close(a, b, step):
    """Communication points equal up to rounding (relative 1e-9 of the larger magnitude)."""
    return abs(a - b) <= 1e-9 * max(abs(a), abs(b), step)


class CallGuard:
    """The FMI 2.0 co-simulation state and argument checks of one slave instance.

    Parameters
    ----------
    slave : pythonfmu.Fmi2Slave
        The slave; its callbacks are replaced by guarded ones.
    interface : SlaveInterface
        Its variable tables (value reference -> name, type, causality, variability).
    """

    def __init__(self, slave, interface):
        self.slave = slave
        self.interface = interface
        self.state = INSTANTIATED
        self.start_time = None
        self.stop_time = None
        self.time = None            # the next communication point [s]
        self.outputs_current = False  # Initialization Mode: outputs reflect what was set
        self.initial_error = None   # why the outputs cannot be computed from what was set
        self.describing = False     # inside to_xml (the build reads start values)
        self.states = SavedStates(self)
        self.fast = FastPath(self)  # the front's values (attached by the front, if there is one)
        self._model = {name: getattr(slave, name) for name in (
            "setup_experiment", "enter_initialization_mode", "exit_initialization_mode",
            "do_step", "terminate", "to_xml", "_get_fmu_state", "_set_fmu_state")}
        self._model_step = self._model["do_step"]
        for name in ("setup_experiment", "enter_initialization_mode", "exit_initialization_mode",
                     "do_step", "terminate", "to_xml", "set_real", "get_real", "set_boolean",
                     "get_boolean", "set_string", "get_string", "set_integer", "get_integer"):
            setattr(slave, name, getattr(self, name))
        slave._get_fmu_state = self.states.get
        slave._set_fmu_state = self.states.set
        # tables of the variables, built at first use: never while the slave's __init__ still
        # declares variables (outputs are checked from Initialization Mode on, the two fast
        # paths run in stepComplete only); the variables never change afterwards
        self._real_outputs = None
        self._real_names = None      # {value reference: name} of the Reals (fmi2GetReal)
        self._real_settable = None   # ... of the Reals settable in stepComplete (fmi2SetReal)

    # ---- logging ----------------------------------------------------------------------------
    def log(self, status, function, text):
        """Log ``text`` for FMI function ``function`` with ``status`` (the front's call status)."""
        self.interface.log(f"{function}: {text}", status)

    def refuse(self, function, text, status=Fmi2Status.error):
        """Log why ``function`` was refused; returns False (doStep: not done)."""
        self.log(status, function, text)
        return False

    def internal(self, function, error, result=None):
        """An unexpected exception: logged as fmi2Error (never passed on); returns ``result``."""
        self.refuse(function, f"internal error, the call did nothing: {type(error).__name__}: {error}")
        return result

    def allowed(self, function, family=None):
        """True if ``function`` may be called now, else log fmi2Error and return False."""
        if self.state in ALLOWED[family or function]:
            return True
        return self.refuse(function, f"illegal call in state '{self.state}'")

    # ---- outputs -----------------------------------------------------------------------------
    def outputs_finite(self):
        """True if every Real output is finite (the invariant a step or restore must keep)."""
        if self._real_outputs is None:
            self._real_outputs = attribute_reader(self.interface.real_output_names())
        values = self._real_outputs(self.slave)
        try:
            total = sum(values)  # finite: all are (one sum, not a call per value) ...
            return total - total == 0.0 or all(map(math.isfinite, values))  # ... or overflowed
        except TypeError:  # not even a number
            return False

    def _run_initialization(self):
        """The model's exitInitializationMode computation; returns an error text or None.

        A ``ValueError`` (bad parameter or input) gives its message, anything else also
        its type.
        """
        try:
            self._model["exit_initialization_mode"]()
        except ValueError as error:
            return str(error)
        except Exception as error:  # noqa: BLE001 - nothing may reach pythonfmu
            return f"{type(error).__name__}: {error}"
        return None if self.outputs_finite() else "the outputs are not finite"

    def _refresh_initial_outputs(self, function):
        """Initialization Mode: recompute the outputs from what was set; False if impossible."""
        if not self.outputs_current:
            self.outputs_current = True
            self.initial_error = self._run_initialization()
        if self.initial_error:
            return self.refuse(function, f"the outputs are undefined: {self.initial_error}")
        return True

    def validity(self, function):
        """Log the stepper's validity-range warning, if its last step or start raised one."""
        try:  # (no getattr with defaults: this runs after every step)
            warning = self.slave.stepper.warning
        except AttributeError:  # no stepper (yet), or one without a validity range
            warning = None
        if warning:
            self.log(Fmi2Status.warning, function, warning)

    # ---- life cycle --------------------------------------------------------------------------
    def setup_experiment(self, start_time, stop_time, tolerance):
        function = "fmi2SetupExperiment"
        if not self.allowed(function):
            return
        if not -_INF < start_time < _INF:
            return self.refuse(function, f"startTime = {start_time!r} s is not finite")
        if stop_time is not None and not (start_time <= stop_time < _INF):
            return self.refuse(function, f"stopTime = {stop_time!r} s is not finite and >= "
                                         f"startTime = {start_time!r} s")
        self.start_time, self.stop_time = start_time, stop_time
        try:
            self._model["setup_experiment"](start_time, stop_time, tolerance)
        except Exception as error:  # noqa: BLE001
            self.refuse(function, f"{type(error).__name__}: {error}")

    def enter_initialization_mode(self):
        if self.allowed("fmi2EnterInitializationMode"):
            self.state, self.outputs_current = INITIALIZATION, False
            try:
                self._model["enter_initialization_mode"]()
            except Exception as error:  # noqa: BLE001
                self.refuse("fmi2EnterInitializationMode", f"{type(error).__name__}: {error}")

    def exit_initialization_mode(self):
        function = "fmi2ExitInitializationMode"
        if not self.allowed(function):
            return
        error = self._run_initialization()
        if error:
            self.outputs_current, self.initial_error = True, error
            return self.refuse(function, f"refused, the instance stays in Initialization Mode: "
                                         f"{error}")
        self.state, self.time = STEP_COMPLETE, self.start_time
        self.validity(function)

    def terminate(self):
        if self.allowed("fmi2Terminate"):
            self.state = TERMINATED
            try:
                self._model["terminate"]()
            except Exception as error:  # noqa: BLE001
                self.refuse("fmi2Terminate", f"{type(error).__name__}: {error}")

    def do_step(self, current_time, step_size):
        fast = self.fast.view
        try:
            if fast is not None and fast[PENDING]:  # inputs the front accepted since the last step
                self.fast.take_inputs()
            return self._do_step(current_time, step_size)
        except Exception as error:  # noqa: BLE001 - nothing may reach pythonfmu
            return self.internal("fmi2DoStep", error, False)
        finally:
            if fast is not None:
                self.fast.write_step()

    def _do_step(self, current_time, step_size):
        """The model-free checks, then :meth:`advance`. The front makes the same checks in C
        (``fast_path.c``: ``direct_step_allowed``) and calls :meth:`advance` directly."""
        function = "fmi2DoStep"
        if self.state is not STEP_COMPLETE and not self.allowed(function):
            return False
        if not (-_INF < current_time < _INF and 0.0 < step_size < _INF):
            return self.refuse(function, f"currentCommunicationPoint = {current_time!r} s and "
                                         f"communicationStepSize = {step_size!r} s must be finite, "
                                         "the step > 0")
        expected = self.time
        if expected is not None and current_time != expected and \
                not _close(current_time, expected, step_size):
            return self.refuse(function, f"currentCommunicationPoint = {current_time!r} s, but the "
                                         f"last step ended at {expected!r} s (the communication "
                                         "points must follow one another)")
        end = current_time + step_size
        stop = self.stop_time
        if stop is not None and end > stop and not _close(end, stop, step_size):
            return self.refuse(function, f"the step to {end!r} s passes stopTime = {stop!r} s")
        return self.advance(current_time, step_size)

    def advance(self, current_time, step_size):
        """A step that passed :meth:`_do_step`'s checks: the model's step, then :meth:`stepped`."""
        try:
            done = bool(self._model_step(current_time, step_size))
        except Exception as error:  # noqa: BLE001 - a step the model rejects is discarded
            return self.discarded(current_time, error)
        return done and self.stepped(current_time, step_size)

    def discarded(self, current_time, error):
        """A step the model rejected (``error``, before any state changed): logged as
        fmi2Discard, "<model> '<instance>': step at t = ... s discarded: <why>"; False."""
        self.interface.log(f"step at t = {current_time!r} s discarded: {error}", Fmi2Status.discard)
        return False

    def stepped(self, current_time, step_size):
        """After a model step that was done: the outputs' finiteness, the next communication
        point and the validity warning; True unless an output is not finite (then the
        instance is in the error state)."""
        function = "fmi2DoStep"
        if not self.outputs_finite():
            self.state = ERROR
            return self.refuse(function, f"internal error: the step at t = {current_time!r} s gave a "
                                         "non-finite output; the instance is in the error state "
                                         "(restore a saved state or reset it)")
        self.time = current_time + step_size
        self.validity(function)
        return True

    def to_xml(self, model_options=None):
        self.describing = True  # pythonfmu's build reads every start value through get_*
        try:
            return self._model["to_xml"]({} if model_options is None else model_options)
        finally:
            self.describing = False

    # ---- variables ---------------------------------------------------------------------------
    def _get(self, function, kind, references, convert, missing):
        """Values of ``references`` of type ``kind``; refused calls log fmi2Error."""
        try:
            return self._values(function, kind, references, convert, missing)
        except Exception as error:  # noqa: BLE001
            return self.internal(function, error, [missing] * len(references))

    def _values(self, function, kind, references, convert, missing):
        if not self.describing:
            if self.state not in ALLOWED["fmi2Get"]:
                self.allowed(function, "fmi2Get")
                return [missing] * len(references)
            if self.state is INITIALIZATION and not self._refresh_initial_outputs(function):
                return [missing] * len(references)
        names = self.interface.names(kind)
        slave, values, unknown = self.slave, [], []
        for reference in references:
            name = names.get(reference)
            if name is None:
                unknown.append(reference)
                values.append(missing)
            else:
                values.append(convert(getattr(slave, name)))
        if unknown:
            self.refuse(function, self._unknown(kind, unknown))
        return values

    def _set(self, function, kind, references, values, check):
        """Set ``references`` of type ``kind`` to ``values``; all or nothing."""
        try:
            self._assign(function, kind, references, values, check)
        except Exception as error:  # noqa: BLE001
            self.internal(function, error)

    def _assign(self, function, kind, references, values, check):
        if self.state not in ALLOWED["fmi2Set"]:
            return self.allowed(function, "fmi2Set")
        settable = self.interface.settable(kind, self.state)
        names = []
        for reference, value in zip(references, values):
            name = settable.get(reference)
            problem = None if name is None else check(value)
            if name is None or problem:
                why = problem or self.interface.setting_refusal(kind, reference, self.state)
                return self.refuse(function, f"{why}; nothing was set (value {shown_value(value)})")
            names.append(name)
        slave = self.slave
        for name, value in zip(names, values):
            setattr(slave, name, value)
        if self.state is INITIALIZATION:
            self.outputs_current = False

    def _unknown(self, kind, references):
        return unknown_references(lambda r: self.interface.describe_reference(kind, r),
                                  references)

    def get_real(self, references):
        # hot path of a running co-simulation: stepComplete, known references (one dict
        # lookup each); anything else takes the checked path, which logs what is wrong
        if self.state is STEP_COMPLETE:
            names = self._real_names
            if names is None:
                names = self._real_names = self.interface.names("Real")
            slave = self.slave
            try:
                return [float(getattr(slave, names[reference])) for reference in references]
            except Exception:  # noqa: BLE001 - an unknown reference: the checked path says which
                pass
        return self._get("fmi2GetReal", "Real", references, float, _NAN)

    def get_boolean(self, references):
        return self._get("fmi2GetBoolean", "Boolean", references, bool, False)

    def get_string(self, references):
        special = self.fast.reference(references)
        if special == DESCRIBE and self.fast.view is None:
            return [self.fast.describe()]
        if special is not None and self.fast.sync(special):
            return [""]
        return self._get("fmi2GetString", "String", references, str, "")

    def get_integer(self, references):
        return self._get("fmi2GetInteger", "Integer", references, int, 0)

    def set_real(self, references, values):
        # hot path: stepComplete, settable references, float values; else the checked path
        if self.state is STEP_COMPLETE:
            settable = self._real_settable
            if settable is None:
                settable = self._real_settable = self.interface.settable("Real", STEP_COMPLETE)
            try:
                names = [settable[reference] for reference in references]
            except Exception:  # noqa: BLE001 - not settable now: the checked path says why
                names = None
            if names is not None and all(value.__class__ is float for value in values):
                slave = self.slave
                for name, value in zip(names, values):
                    setattr(slave, name, value)
                return
        self._set("fmi2SetReal", "Real", references, values, _check_real)

    def set_boolean(self, references, values):
        self._set("fmi2SetBoolean", "Boolean", references, values, _check_boolean)

    def set_string(self, references, values):
        if self.fast.reference(references) == ATTACH and self.fast.view is None:
            try:
                return self.fast.attach(values[0])
            except Exception:  # noqa: BLE001 - not attached: every call takes the guard's path
                self.fast.view = None
                return None
        self._set("fmi2SetString", "String", references, values, _check_string)

    def set_integer(self, references, values):
        self._set("fmi2SetInteger", "Integer", references, values, _check_integer)


def _check_real(value):
    return None if isinstance(value, float) else f"{value!r} is not a Real"


def _check_boolean(value):
    return None if isinstance(value, bool) else f"{value!r} is not a Boolean"


def _check_string(value):
    return None if isinstance(value, str) else "the string is NULL"


def _check_integer(value):
    return None if isinstance(value, int) else f"{value!r} is not an Integer"
