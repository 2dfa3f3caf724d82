"""Saved FMU states (fmi2GetFMUstate / SetFMUstate / (De)SerializeFMUstate) that are checked.

A state is a JSON-ready dict: every variable's value (pythonfmu's part), the stepper's
hidden state under ``__stepper__`` (the slave's ``_get_fmu_state``) and, under
``__fmi__``, the FMU's model name, its wire's digest, its GUID, the calling-sequence state
and the communication point.

Restoring checks everything before it changes anything: the model and the wire must be
this FMU's (a state saved with another parameter file is refused naming both digests, in
the words of the C family, c_family/core/layer_state_bytes.c), then the GUID (another
build: another version or code), every
variable must be present with its type, nothing unknown may be there, a state after
initialization (stepComplete, terminated) must hold the stepper's hidden state, and the
stepper must take it back unchanged (it is saved again and compared). If a check or the
restore fails, the instance is put back as it was and fmi2Error is logged.
Bytes that are not JSON become a state that is refused when it is set (pythonfmu calls
the byte conversions on the class, where no instance can log).
"""
import json
import math
import os
import re

from .lifecycle import STATES, STEP_COMPLETE, TERMINATED

__all__ = ["SavedStates", "state_to_bytes", "state_from_bytes", "state_with", "split_state"]

_META = "__fmi__"
_STEPPER = "__stepper__"
_INVALID = "__invalid__"
_KINDS = {"Real": (float, int), "Boolean": (bool,), "String": (str,), "Integer": (int,)}


def state_with(state, stepper):
    """Add a stepper's hidden state to pythonfmu's variable state (JSON-ready); returns it."""
    state[_STEPPER] = None if stepper is None else stepper.state()
    return state


def split_state(state):
    """(variable state, stepper state) of a state made by :func:`state_with`."""
    variables = dict(state)
    return variables, variables.pop(_STEPPER, None)


def state_to_bytes(state):
    """JSON bytes of a state (pythonfmu's SerializeFMUstate); never raises."""
    try:
        return json.dumps(state).encode("utf-8")
    except Exception as error:  # noqa: BLE001 - becomes a state refused when set
        return json.dumps({_INVALID: f"the state could not be serialized: {error}"}).encode()


def state_from_bytes(data):
    """A state from :func:`state_to_bytes` bytes (DeSerializeFMUstate); never raises."""
    try:
        state = json.loads(bytes(data).decode("utf-8"))
    except Exception as error:  # noqa: BLE001 - RecursionError, UnicodeDecodeError, ...
        return {_INVALID: f"the bytes are not a serialized state ({type(error).__name__})"}
    return state if isinstance(state, dict) else {_INVALID: "the bytes are not a serialized state"}


def _read_guid(resources):
    """The guid of ``<resources>/../modelDescription.xml``, or None if it cannot be read."""
    try:
        with open(os.path.join(resources, os.pardir, "modelDescription.xml"), encoding="utf-8") as file:
            match = re.search(r'\sguid="([^"]*)"', file.read(8192))
    except (OSError, TypeError, ValueError):
        return None
    return match.group(1) if match else None


def _json_like(value, depth=0):
    """True if ``value`` is made of dicts, lists, str, bool, None and finite numbers."""
    if depth > 20:
        return False
    if value is None or isinstance(value, (str, bool, int)):
        return True
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, list):
        return all(_json_like(item, depth + 1) for item in value)
    if isinstance(value, dict):
        return all(isinstance(k, str) and _json_like(v, depth + 1) for k, v in value.items())
    return False


class SavedStates:
    """fmi2GetFMUstate / fmi2SetFMUstate of one guarded slave (see the module docstring)."""

    def __init__(self, guard):
        self.guard = guard
        self._guid = False  # not read yet

    @property
    def guid(self):
        """This FMU's GUID (from the unpacked modelDescription.xml), or None if unknown."""
        if self._guid is False:
            self._guid = _read_guid(self.guard.slave.resources)
        return self._guid

    def get(self):
        """The instance's whole state (pythonfmu's fmi2GetFMUstate callback); never raises."""
        guard = self.guard
        try:
            state = dict(guard._model["_get_fmu_state"]())
        except Exception as error:  # noqa: BLE001
            guard.refuse("fmi2GetFMUstate", f"{type(error).__name__}: {error}")
            return {_INVALID: "the state could not be saved"}
        state[_META] = {"model": guard.slave.modelName, "wire": guard.interface.digest,
                        "guid": self.guid, "state": guard.state, "time": guard.time,
                        "start_time": guard.start_time, "stop_time": guard.stop_time,
                        "outputs_current": guard.outputs_current,
                        "initial_error": guard.initial_error}
        return state

    def _problem(self, state):
        """Why ``state`` cannot be restored into this instance, or None."""
        if not isinstance(state, dict):
            return "not a state of this FMU"
        if _INVALID in state:
            return state[_INVALID]
        meta = state.get(_META)
        if not isinstance(meta, dict) or meta.get("state") not in STATES:
            return "not a state saved by this FMU (no valid __fmi__ entry)"
        model = self.guard.slave.modelName
        if meta.get("model") != model:
            return f"the state was saved by model '{meta.get('model')}', this FMU is '{model}'"
        digest = self.guard.interface.digest
        if meta.get("wire") != digest:
            return (f"the state was saved by an FMU of another wire ({meta.get('wire')}); this "
                    f"FMU's wire is {digest}: restore it into an FMU built from the same "
                    f"parameter file")
        if self.guid is not None and meta.get("guid") != self.guid:
            return (f"the state was saved by another FMU build (GUID {meta.get('guid')!r}, this FMU "
                    f"is {self.guid!r}): another version or model")
        for key in ("time", "start_time", "stop_time"):
            value = meta.get(key)
            if value is not None and not (isinstance(value, (int, float)) and math.isfinite(value)):
                return f"__fmi__.{key} = {value!r} is not a finite number"
        expected = self.guard.interface.variable_kinds()
        unknown = sorted(set(state) - set(expected) - {_META, _STEPPER})
        if unknown:
            return f"unknown entries {', '.join(map(repr, unknown[:5]))}"
        for name, kind in expected.items():
            if name not in state:
                return f"variable {name!r} is missing"
            value = state[name]
            if isinstance(value, bool) and kind != "Boolean" or not isinstance(value, _KINDS[kind]):
                return f"variable {name!r} = {value!r} is not a {kind}"
        if not _json_like(state.get(_STEPPER)):
            return "the hidden model state holds a value that is not a finite number, text or list"
        if meta["state"] in (STEP_COMPLETE, TERMINATED) and state.get(_STEPPER) is None:
            # only a forged state: an initialized instance always has a stepper
            return f"a state in '{meta['state']}' must hold the hidden model state ({_STEPPER} is null)"
        return None

    def set(self, state):
        """Restore ``state`` (pythonfmu's fmi2SetFMUstate callback); all or nothing, never raises."""
        try:
            self._set(state)
        except Exception as error:  # noqa: BLE001 - nothing may reach pythonfmu
            self.guard.internal("fmi2SetFMUstate", error)

    def _set(self, state):
        guard, function = self.guard, "fmi2SetFMUstate"
        problem = self._problem(state)
        if problem is None:
            before = self.get()
            problem = self._restore(state)
            if problem is not None:
                self._restore(before)  # put the instance back as it was
        if problem is not None:
            guard.refuse(function, f"state refused, the instance is unchanged: {problem}")

    def _restore(self, state):
        """Apply a checked ``state``; returns a problem text (then the caller rolls back)."""
        guard, meta = self.guard, state[_META]
        try:
            guard._model["_set_fmu_state"]({k: v for k, v in state.items() if k != _META})
            saved_again = guard._model["_get_fmu_state"]().get(_STEPPER)
        except Exception as error:  # noqa: BLE001
            return f"the model could not take it back ({type(error).__name__}: {error})"
        if saved_again != state.get(_STEPPER):
            return "the hidden model state is corrupt (the model does not save it back unchanged)"
        guard.state = STATES[STATES.index(meta["state"])]  # the constant (compared with `is`)
        guard.time = meta["time"]
        guard.start_time, guard.stop_time = meta["start_time"], meta["stop_time"]
        guard.outputs_current = bool(meta.get("outputs_current"))
        guard.initial_error = meta.get("initial_error")
        if guard.state in (STEP_COMPLETE, TERMINATED) and not guard.outputs_finite():
            return "the outputs it gives are not finite"
        return None
