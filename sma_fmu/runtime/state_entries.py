"""Reading a stepper's saved state as carefully as an input (the steppers' ``restore``).

A saved state may come back edited (a host's serialized FMU state, a study's checkpoint).
Every entry is checked for kind and range before a stepper changes anything, and a refusal
names the entry and the value, so a state is either taken whole or refused whole.
"""
import math

from .constants import KELVIN_OFFSET

__all__ = ["StateError", "check_format", "read_entries", "read_number", "read_optional_number",
           "read_temperature", "read_direction", "require_pair"]


class StateError(ValueError):
    """A saved state is malformed; the message names the entry and what is wrong."""


def check_format(state, expected, what):
    """Refuse a state whose ``format`` entry is not ``expected`` (e.g. one saved by an earlier
    build, with a one-reversal minor-loop memory): it is never misread."""
    found = state.get("format") if isinstance(state, dict) else None
    if found != expected:
        raise StateError(
            f"the {what} has format {found!r}, not {expected!r}: it was saved by an earlier "
            "sma-fmu build (minor-loop memory of one reversal) and cannot be restored by this one")


def read_entries(state, required, optional=(), what="state"):
    """Check that ``state`` is a dict with every ``required`` key and no key outside
    ``required`` + ``optional``; returns it."""
    if not isinstance(state, dict):
        raise StateError(f"the {what} must be a JSON object, got {type(state).__name__}")
    missing = [key for key in required if key not in state]
    if missing:
        raise StateError(f"the {what} lacks entr{'y' if len(missing) == 1 else 'ies'} "
                         f"{', '.join(missing)}")
    unknown = sorted(set(state) - set(required) - set(optional))
    if unknown:
        raise StateError(f"the {what} has unknown entr{'y' if len(unknown) == 1 else 'ies'} "
                         f"{', '.join(map(str, unknown))}")
    return state


def read_number(state, key, low=-math.inf, high=math.inf, unit=""):
    """``state[key]`` as a float: a finite number (not a bool) in [low, high], else StateError."""
    value = state[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise StateError(f"state entry {key} must be a number{f' [{unit}]' if unit else ''}, "
                         f"got {value!r:.80}")
    number = float(value)
    if not (math.isfinite(number) and low <= number <= high):
        raise StateError(f"state entry {key} = {value!r} must be finite and in "
                         f"[{low:g}, {high:g}]{f' {unit}' if unit else ''}")
    return number


def read_optional_number(state, key, low=-math.inf, high=math.inf, unit=""):
    """:func:`read_number`, or None where the entry is None (a memory not yet filled)."""
    return None if state[key] is None else read_number(state, key, low, high, unit)


def read_temperature(state, key, high=math.inf, optional=False):
    """``state[key]`` as a temperature [degC] above absolute zero and at most ``high``
    (None where ``optional`` and the entry is None), else StateError."""
    if optional and state[key] is None:
        return None
    temperature = read_number(state, key, -KELVIN_OFFSET, high, "degC")
    if temperature == -KELVIN_OFFSET:
        raise StateError(f"state entry {key} = {temperature!r} degC must be above -273.15 degC")
    return temperature


def read_direction(state, key="direction"):
    """``state[key]`` as +1 (heating) or -1 (cooling), else StateError."""
    value = state[key]
    if isinstance(value, bool) or value not in (1, -1):
        raise StateError(f"state entry {key} must be 1 (heating) or -1 (cooling), got {value!r:.80}")
    return int(value)


def require_pair(first_key, first, second_key, second, what="state"):
    """Refuse (StateError) a pair of entries read as optional numbers where one is None and
    the other is not: they are one memory, filled together (``what`` names whose entries)."""
    if (first is None) != (second is None):
        raise StateError(f"{what} entries {first_key} and {second_key} must both be numbers or "
                         f"both be null")
