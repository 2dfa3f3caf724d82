"""A scenario's signals as a co-simulation source, and their text form for FMI String parameters.

FMI 2.0 has no array parameters, so the SmaScenarioSignals FMU takes a scenario's
``[reference]`` and ``[load]`` tables as two String parameters, each holding its table as
a JSON object with the scenario file's keys (units in the key names)::

    reference    = {"kind":"cosine","offset_ohm":41.85,"amplitude_ohm":6.05,"frequency_hz":0.5}
    load_profile = {"times_s":[0.0,10.0,20.0],"values_kg":[0.0032,0.05,0.15]}

The same functions check them as check scenario files (:mod:`.signals`), so a table that
a scenario file accepts works in the FMU, and the error messages are the same.

**choice** (the time grid): a host that adds up its time (t + h + h + ...) passes
communication points a few rounding errors off k h, the library loop's t_k. A table
reference held until t_k and ramped after it then gives, a rounding error after t_k, a
value 1e-14 ohm off the hold, and a compensator that takes the reference's direction from
the sign of its change switches branch a step early (16 ohm apart on the set-point
scenarios). So :class:`SignalSource` samples at start + k h, h the size of its first step,
whenever the end of a step lies within :data:`GRID_TOLERANCE` steps of that point;
elsewhere (variable steps) at the host's time. The first step, not each step's size: a
host that steps from t to t_next passes t_next - t, which differs from h by rounding
errors too (OMSimulator does).
"""
import json
from collections import namedtuple

from .checks import fast_finite, fast_positive, require_finite
from .signals import load_from_table, reference_from_table
from .state_entries import read_entries, read_number

__all__ = ["GRID_TOLERANCE", "SignalOutputs", "SignalSource", "table_text", "signals_from_text",
           "grid_point", "grid_time"]

GRID_TOLERANCE = 1e-6  # [steps]: a time this close to start + k h is taken as that point

SignalOutputs = namedtuple("SignalOutputs", ["R_ref", "load"])
SignalOutputs.__doc__ = "Reference resistance R_ref [ohm] and load [kg] at one time."


def table_text(table):
    """A signal table as compact JSON: no spaces, because FMU containers split start values at spaces."""
    return json.dumps(table, separators=(",", ":"), allow_nan=False)


def _table(name, text):
    if not isinstance(text, str):
        raise ValueError(f"{name} must be a JSON object in a string, got {text!r}")
    try:
        table = json.loads(text)
    except (ValueError, RecursionError) as error:
        raise ValueError(f"{name} is not valid JSON ({error}): {text!r}") from None
    if not isinstance(table, dict):
        raise ValueError(f"{name} must be a JSON object, got {text!r}")
    return table


def signals_from_text(reference_text, load_text):
    """(ReferenceSignal, LoadProfile) from the two JSON texts; ``ValueError`` names the parameter."""
    signals = []
    for name, text, build in (("reference", reference_text, reference_from_table),
                              ("load_profile", load_text, load_from_table)):
        try:
            signals.append(build(_table(name, text)))
        except ValueError as error:
            message = str(error)
            raise ValueError(message if message.startswith(name) else f"{name}: {message}") from None
    if signals[0].quantity != "resistance":   # it has no wire to map a stroke through
        raise ValueError(f"reference: quantity {signals[0].quantity!r} is not taken here; "
                         f"this source gives a resistance reference in ohm")
    return tuple(signals)


def grid_point(time_s, start_s, step_s):
    """``start_s`` + k ``step_s`` [s] for the k nearest ``time_s`` [s] if ``time_s`` lies within
    :data:`GRID_TOLERANCE` steps of it, else None."""
    steps = (time_s - start_s) / step_s
    if not abs(steps) < 2.0 ** 52:  # beyond the integers a float holds (or inf, nan)
        return None
    grid = start_s + round(steps) * step_s
    return grid if abs(time_s - grid) <= GRID_TOLERANCE * step_s else None


def grid_time(time_s, start_s, step_s):
    """:func:`grid_point` of ``time_s`` [s], or ``time_s`` itself when it is off the grid."""
    grid = grid_point(time_s, start_s, step_s)
    return time_s if grid is None else grid


class SignalSource:
    """R_ref(t) [ohm] and the load f(t) [kg] at the communication points of a co-simulation.

    Parameters
    ----------
    reference : ReferenceSignal
    load : LoadProfile
    start_time : float
        Start time [s]; the outputs before the first step are those at this time.

    After :meth:`step` (t, h) the outputs are those at t + h: a plot of them against the
    communication points shows R_ref(t) and f(t) exactly. t + h is taken on the grid
    start + k h_0, h_0 the first step's size, when it lies within :data:`GRID_TOLERANCE`
    steps of it (see the module docstring).
    """

    def __init__(self, reference, load, start_time=0.0):
        self.reference = reference
        self.load = load
        self.start_time = self.time = require_finite("start time", start_time)
        self.grid_step = None  # h_0 [s], from the first step (the FMU adapters set the run's h_0)
        self.outputs = self._sample(self.time)

    def _sample(self, time_s):
        return SignalOutputs(self.reference.value(time_s), self.load.value(time_s))

    def step(self, current_time, step_size):
        """Advance from ``current_time`` [s] by ``step_size`` [s]; returns the outputs at the end."""
        end = fast_finite("current time", current_time) + fast_positive("step_size", step_size)
        if self.grid_step is None:
            self.grid_step = step_size
        end = grid_time(fast_finite("current time + step_size", end), self.start_time,
                        self.grid_step)
        self.outputs = self._sample(end)
        self.time = end
        return self.outputs

    def state(self):
        """JSON-ready hidden state (the time of the outputs [s])."""
        return {"time": self.time}

    def restore(self, state):
        """Restore a state saved by :meth:`state` (``ValueError`` naming a bad entry; no change)."""
        read_entries(state, ("time",), what="signals state")
        time = read_number(state, "time", 0.0, unit="s")
        outputs = self._sample(time)
        self.time, self.outputs = time, outputs
