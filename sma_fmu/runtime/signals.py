"""Scenario signals: the reference R_ref(t) [ohm] and the piecewise-constant load f(t) [kg].

Built from the ``[reference]`` and ``[load]`` tables of a scenario file. Problems raise
``ValueError`` naming the key; the scenario loader adds the file and section.

A reference of ``quantity = "stroke"`` is a stroke [mm] (contraction from the start length)
with the same kinds, its keys ending in ``_mm`` instead of ``_ohm``; :mod:`.stroke` maps it
to R_ref through the model.
"""
import bisect
import math

__all__ = ["REFERENCE_KINDS", "unit_key", "MAX_REFERENCE_OHM", "MAX_STROKE_MM", "QUANTITIES", "is_stroke", "ReferenceSignal", "LoadProfile", "reference_from_table",
           "load_from_table"]

MAX_REFERENCE_OHM = 1e6  # a wire's resistance is ohms to kilo-ohms; beyond this is a typo
MAX_STROKE_MM = 1e4      # |stroke| [mm]: a wire's stroke is millimetres; beyond this is a typo
QUANTITIES = {"resistance": "ohm", "stroke": "mm"}   # quantity -> unit of its keys


def is_stroke(reference):
    """Whether ``reference`` (a scenario's) is a stroke [mm], mapped to R_ref through the
    model, rather than R_ref [ohm] itself."""
    return getattr(reference, "quantity", None) == "stroke"

# kind -> (required keys, optional keys with defaults)
REFERENCE_KINDS = {
    "constant": (("value_ohm",), {}),
    "step": (("initial_ohm", "final_ohm", "time_s"), {}),
    "ramp": (("start_ohm", "end_ohm", "start_time_s", "end_time_s"), {}),
    "sine": (("offset_ohm", "amplitude_ohm", "frequency_hz"), {"phase_deg": 0.0}),
    "cosine": (("offset_ohm", "amplitude_ohm", "frequency_hz"), {"phase_deg": 0.0}),
    "table": (("times_s", "values_ohm"), {}),
}


def _number(table, key):
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{key} must be a finite number, got {value!r}")
    return float(value)


def _numbers(table, key):
    values = table[key]
    if not isinstance(values, list) or not values:
        raise ValueError(f"{key} must be a non-empty list of numbers, got {values!r}")
    return [_number({key: v}, key) for v in values]


def _increasing(times, key):
    if any(b <= a for a, b in zip(times, times[1:])):
        raise ValueError(f"{key} must be strictly increasing, got {times!r}")


def unit_key(key, unit):
    """``key`` of :data:`REFERENCE_KINDS` (unit ohm) with its unit suffix for ``unit``."""
    return key[:-3] + unit if key.endswith("_ohm") else key


class ReferenceSignal:
    """R_ref(t) [ohm], or a stroke [mm] (``quantity`` "stroke"): one of
    :data:`REFERENCE_KINDS`, with its settings (keys in the quantity's unit)."""

    def __init__(self, kind, settings, quantity="resistance"):
        self.kind = kind
        self.quantity = quantity
        self.unit = QUANTITIES[quantity]
        self.settings = dict(settings)
        # the values under the kinds' own keys (..._ohm), whatever the unit
        self._s = s = {key[:-len(self.unit)] + "ohm" if key.endswith("_" + self.unit) else key:
                       value for key, value in self.settings.items()}
        if kind == "table":
            self._times, self._values = s["times_s"], s["values_ohm"]
        lowest, highest = self.bounds()
        if quantity == "stroke":
            if not max(-lowest, highest) <= MAX_STROKE_MM:
                raise ValueError(f"the stroke reference must stay within +-{MAX_STROKE_MM:g} mm, "
                                 f"but reaches {lowest!r} ... {highest!r} mm")
            return
        if not lowest > 0.0:
            raise ValueError(f"the reference must stay > 0 ohm, but reaches {lowest!r} ohm")
        if not highest <= MAX_REFERENCE_OHM:
            raise ValueError(f"the reference must stay <= {MAX_REFERENCE_OHM:g} ohm, "
                             f"but reaches {highest!r} ohm")

    def bounds(self):
        """(lowest, highest) value of the reference over all time [its unit: ohm or mm]."""
        s = self._s
        if self.kind == "constant":
            values = [s["value_ohm"]]
        elif self.kind == "step":
            values = [s["initial_ohm"], s["final_ohm"]]
        elif self.kind == "ramp":
            values = [s["start_ohm"], s["end_ohm"]]
        elif self.kind in ("sine", "cosine"):
            values = [s["offset_ohm"] - abs(s["amplitude_ohm"]), s["offset_ohm"] + abs(s["amplitude_ohm"])]
        else:
            values = self._values
        return min(values), max(values)

    def value(self, t):
        """The reference [ohm, or mm for a stroke] at time ``t`` [s]."""
        s = self._s
        if self.kind == "constant":
            return s["value_ohm"]
        if self.kind == "step":
            return s["final_ohm"] if t >= s["time_s"] else s["initial_ohm"]
        if self.kind == "ramp":
            t0, t1 = s["start_time_s"], s["end_time_s"]
            share = min(1.0, max(0.0, (t - t0) / (t1 - t0)))
            return s["start_ohm"] + share * (s["end_ohm"] - s["start_ohm"])
        if self.kind in ("sine", "cosine"):
            wave = math.sin if self.kind == "sine" else math.cos
            angle = 2.0 * math.pi * s["frequency_hz"] * t + math.radians(s["phase_deg"])
            return s["offset_ohm"] + s["amplitude_ohm"] * wave(angle)
        return _interpolate(self._times, self._values, t)

    def values(self, times):
        """:meth:`value` at each of ``times`` [s], as a list: the same numbers, a constant
        reference's without a call per time (a run's rows, 30 000 of them at 1 ms)."""
        if self.kind == "constant":
            return [self._s["value_ohm"]] * len(times)
        return list(map(self.value, times))

    def trend(self, t):
        """+1 or -1 [1]: the sign of the change the reference last made at or before ``t`` [s]
        (its slope at t where it moves; +1 while it never moved). A pure function of t, so a
        host's step size or a restored state never changes it."""
        s = self._s
        kind = self.kind
        if kind == "step":
            change = s["final_ohm"] - s["initial_ohm"] if t >= s["time_s"] else 0.0
        elif kind == "ramp":
            change = s["end_ohm"] - s["start_ohm"] if t > s["start_time_s"] else 0.0
        elif kind in ("sine", "cosine"):
            angle = 2.0 * math.pi * s["frequency_hz"] * t + math.radians(s["phase_deg"])
            slope, curvature = ((math.cos(angle), -math.sin(angle)) if kind == "sine"
                                else (-math.sin(angle), -math.cos(angle)))
            # at a turn (slope 0) the curvature says where it came from: a maximum, rising
            change = s["amplitude_ohm"] * s["frequency_hz"] * (slope or -curvature)
        elif kind == "table":
            change, last = 0.0, bisect.bisect_left(self._times, t)   # knots before t
            for i in range(min(last, len(self._values) - 1) - 1, -1, -1):
                change = self._values[i + 1] - self._values[i]
                if change:
                    break
        else:
            change = 0.0
        return -1 if change < 0.0 else 1

    def as_table(self):
        """The scenario file's ``[reference]`` table of this signal (kind and settings)."""
        quantity = {} if self.quantity == "resistance" else {"quantity": self.quantity}
        return {"kind": self.kind, **quantity, **self.settings}


def _interpolate(times, values, t):
    if t <= times[0]:
        return values[0]
    if t >= times[-1]:
        return values[-1]
    i = bisect.bisect_right(times, t) - 1
    share = (t - times[i]) / (times[i + 1] - times[i])
    return values[i] + share * (values[i + 1] - values[i])


class LoadProfile:
    """Piecewise-constant load: ``values_kg[i]`` from ``times_s[i]`` on (the first time is 0 s)."""

    def __init__(self, times, values):
        self.times = list(times)
        self.values = list(values)

    def value(self, t, tolerance=1e-9):
        """Load [kg] at ``t`` [s]; a switching time within ``tolerance`` [s] counts as reached."""
        return self.values[bisect.bisect_right(self.times, t + tolerance) - 1]

    def segments(self, stop_time):
        """[(start [s], end [s], load [kg])] of the segments that begin before ``stop_time``."""
        ends = self.times[1:] + [math.inf]
        return [(start, min(end, stop_time), value)
                for start, end, value in zip(self.times, ends, self.values) if start < stop_time]

    def as_table(self):
        """The scenario file's ``[load]`` table of this profile."""
        return {"times_s": list(self.times), "values_kg": list(self.values)}


def reference_from_table(table):
    """A :class:`ReferenceSignal` from a scenario's ``[reference]`` table (``quantity``:
    one of :data:`QUANTITIES`, default "resistance"; a stroke's keys end in ``_mm``)."""
    kind = table.get("kind")
    if kind not in REFERENCE_KINDS:
        raise ValueError(f"kind must be one of {', '.join(REFERENCE_KINDS)}, got {kind!r}")
    quantity = table.get("quantity", "resistance")
    if quantity not in QUANTITIES:
        raise ValueError(f"quantity must be one of {', '.join(QUANTITIES)}, got {quantity!r}")
    unit = QUANTITIES[quantity]
    required, optional = REFERENCE_KINDS[kind]
    required = tuple(unit_key(key, unit) for key in required)
    unknown = sorted(set(table) - set(required) - set(optional) - {"kind", "quantity"})
    if unknown:
        raise ValueError(f"unknown key(s) {', '.join(unknown)} for kind {kind!r}; expected "
                         f"{', '.join(required + tuple(optional))}")
    missing = [key for key in required if key not in table]
    if missing:
        raise ValueError(f"missing key(s) {', '.join(missing)} for kind {kind!r}")
    settings = dict(optional)
    for key in table:
        if key in ("kind", "quantity"):
            continue
        settings[key] = _numbers(table, key) if key.startswith(("times", "values")) else _number(table, key)
    if kind == "table":
        values = unit_key("values_ohm", unit)
        if len(settings["times_s"]) != len(settings[values]):
            raise ValueError(f"times_s and {values} must have the same length")
        _increasing(settings["times_s"], "times_s")
    if kind == "ramp" and not settings["end_time_s"] > settings["start_time_s"]:
        raise ValueError("end_time_s must be after start_time_s")
    if kind in ("sine", "cosine") and settings["frequency_hz"] < 0.0:
        raise ValueError(f"frequency_hz must be >= 0, got {settings['frequency_hz']!r}")
    return ReferenceSignal(kind, settings, quantity)


def load_from_table(table):
    """A :class:`LoadProfile` from a scenario's ``[load]`` table (times_s, values_kg)."""
    unknown = sorted(set(table) - {"times_s", "values_kg"})
    if unknown:
        raise ValueError(f"unknown key(s) {', '.join(unknown)}; expected times_s, values_kg")
    for key in ("times_s", "values_kg"):
        if key not in table:
            raise ValueError(f"missing key {key}")
    times, values = _numbers(table, "times_s"), _numbers(table, "values_kg")
    if len(times) != len(values):
        raise ValueError("times_s and values_kg must have the same length")
    if times[0] != 0.0:
        raise ValueError(f"times_s must start at 0, got {times[0]!r}")
    _increasing(times, "times_s")
    negative = [v for v in values if v < 0.0]
    if negative:
        raise ValueError(f"values_kg must be >= 0, got {negative[0]!r}")
    return LoadProfile(times, values)
