"""Argument checks that raise ``ValueError`` naming the argument and the offending value.

Every public model function validates its physical inputs with these, so bad input
(NaN, inf, negative load or power, unknown direction or mode) never propagates silently.
"""
import math

from .constants import COOLING, HEATING

__all__ = [
    "require_finite", "require_nonnegative", "require_positive",
    "direction_sign", "direction_name", "require_mode", "HYSTERESIS_MODES",
    "fast_finite", "fast_nonnegative", "fast_positive",
]

HYSTERESIS_MODES = ("switch", "continuous")

_DIRECTION_NAMES = {"heating": HEATING, "cooling": COOLING}


def _as_float(name, value):
    if isinstance(value, bool):
        raise ValueError(f"{name} must be a number, got {value!r}")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    return number


def require_finite(name, value):
    """Return ``value`` as float; raise ``ValueError`` if it is not a finite number."""
    number = _as_float(name, value)
    if not math.isfinite(number):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return number


def require_nonnegative(name, value):
    """Return ``value`` as float; raise ``ValueError`` unless finite and >= 0."""
    number = require_finite(name, value)
    if number < 0.0:
        raise ValueError(f"{name} must be >= 0, got {value!r}")
    return number


def require_positive(name, value):
    """Return ``value`` as float; raise ``ValueError`` unless finite and > 0."""
    number = require_finite(name, value)
    if number <= 0.0:
        raise ValueError(f"{name} must be > 0, got {value!r}")
    return number


def direction_sign(direction, name="direction"):
    """Map ``"heating"``/``"cooling"`` or ``+1``/``-1`` to the sign d of dT/dt (+1 or -1)."""
    if isinstance(direction, str):
        key = direction.strip().lower()
        if key in _DIRECTION_NAMES:
            return _DIRECTION_NAMES[key]
    elif not isinstance(direction, bool) and direction in (HEATING, COOLING):
        return int(direction)
    raise ValueError(f"{name} must be 'heating' (+1) or 'cooling' (-1), got {direction!r}")


def direction_name(sign):
    """Inverse of :func:`direction_sign`: +1 -> ``"heating"``, -1 -> ``"cooling"``."""
    return "heating" if direction_sign(sign) == HEATING else "cooling"


def require_mode(mode, name="mode"):
    """Return the hysteresis mode if it is one of :data:`HYSTERESIS_MODES`, else raise."""
    if isinstance(mode, str) and mode in HYSTERESIS_MODES:
        return mode
    raise ValueError(f"{name} must be one of {', '.join(HYSTERESIS_MODES)}, got {mode!r}")


_INF = float("inf")


def fast_finite(name, value):
    """:func:`require_finite` with a fast path for plain finite numbers (stepper hot path)."""
    try:
        if -_INF < value < _INF:
            return value
    except TypeError:
        pass
    return require_finite(name, value)


def fast_nonnegative(name, value):
    """:func:`require_nonnegative` with a fast path for plain finite numbers (stepper hot path)."""
    try:
        if 0.0 <= value < _INF:
            return value
    except TypeError:
        pass
    return require_nonnegative(name, value)


def fast_positive(name, value):
    """:func:`require_positive` with a fast path for plain finite numbers (stepper hot path)."""
    try:
        if 0.0 < value < _INF:
            return value
    except TypeError:
        pass
    return require_positive(name, value)
