"""N feedforward compensators (:class:`~sma_fmu.runtime.feedforward.FeedforwardStepper`) at once.

The compensator is open loop: its output at step k depends only on R_ref(t_k), f(t_k) and
its own memory (d_ref, the minor-loop reversal, the filter), never on the plant. So the
inverse of :mod:`~sma_fmu.runtime.sensing` (major branch of the reference direction, at the
measured or the fixed model load, with the saturation clamp; for ``inverse = "minor-loop"``
the minor branch after the compensator's last reversal, :mod:`.batch_minor_loops`) is
computed for a whole chunk of steps in a few numpy calls, once per distinct compensator
(runs that differ only in gains or filter share it), and only the phase-lag filter
(Tustin, started in steady state) runs step by step, per run. The operations are those of
the scalar code, in its order; tests/test_batch.py binds the two.
"""
import numpy as np

from sma_fmu.runtime.phase_lag import tustin_coefficients
from sma_fmu.studies.batch_minor_loops import (MinorLoopMemory, clamp_fractions,
                                               temperature_of_fractions)

__all__ = ["BatchFeedforward", "FeedforwardChunk"]


class FeedforwardChunk:
    """Compensator outputs for steps ``start`` ... ``start + c - 1``, each (c, N).

    P_ff [W] (0 for "pi" runs), T_ref [degC] (nan for "pi"), saturated (bool);
    ``diverged``: {run: message} where the inverse has no temperature.
    """

    def __init__(self, P_ff, T_ref, saturated, diverged):
        self.P_ff, self.T_ref, self.saturated, self.diverged = P_ff, T_ref, saturated, diverged


def _inverse_key(scenario, reference_group, wires):
    """What the inverse depends on: model parameters, reference, inverse, and the load it uses.

    ``wires`` maps id(parameters) -> their values, so a shared parameter set is read once.
    """
    c = scenario.controller
    load = tuple(scenario.load.times) + tuple(scenario.load.values) if c.adapt_to_load \
        else c.model_load
    params = scenario.compensator_params
    if id(params) not in wires:
        wires[id(params)] = tuple(params.values().items())
    return wires[id(params)], reference_group, c.inverse, c.adapt_to_load, load


class BatchFeedforward:
    """Compensators of the feedforward runs of a batch (the "pi" runs get P_ff = 0 W)."""

    def __init__(self, inputs, scenarios):
        self.inputs = inputs
        self.runs = np.array([i for i, s in enumerate(scenarios) if s.controller.feedforward],
                             dtype=int)
        self._leading = bool(np.array_equal(self.runs, np.arange(self.runs.size)))  # slices
        keys, self.of_run, chosen, wires = {}, [], [], {}
        for run in self.runs:
            key = _inverse_key(scenarios[run], inputs.reference_group[run], wires)
            if key not in keys:
                keys[key] = len(keys)
                chosen.append(run)
            self.of_run.append(keys[key])
        self.of_run = np.array(self.of_run, dtype=int)     # inverse column of each ff run
        self.columns = np.array(chosen, dtype=int)          # a run that stands for each inverse
        self._tables([scenarios[run] for run in chosen])
        minor = np.array([scenarios[run].controller.inverse == "minor-loop" for run in chosen],
                         dtype=bool)
        self.minor = MinorLoopMemory(np.flatnonzero(minor)) if minor.any() else None
        coefficients = [tustin_coefficients(scenarios[run].controller.alpha,
                                            scenarios[run].controller.beta, inputs.step_s)
                        for run in self.runs]
        self.b0, self.b1, self.a1 = (np.array(c) for c in zip(*coefficients)) if coefficients \
            else (np.empty(0),) * 3
        self.previous_input = None   # v_(k-1) per feedforward run
        self.previous_output = None  # y_(k-1)

    def _tables(self, chosen):
        """Per (table row, inverse): the terms of the inverse that do not depend on R_ref."""
        table, runs = self.inputs.compensator_constants, self.columns
        column = lambda values: np.array(values, dtype=float)  # noqa: E731
        p = [s.compensator_params for s in chosen]
        self.span = column([q.R_MF - q.R_P for q in p])
        self.T_room = column([q.T_room for q in p])
        self.gain = column([q.K_th for q in p])
        self.adaptive = np.array([s.controller.adapt_to_load for s in chosen], dtype=bool)
        M = table["M"][:, runs]
        hot = column([q.R_P for q in p]) + table["xi_F_min"][:, runs] * column(
            [q.R_F - q.R_P for q in p])
        delta = column([q.saturation_margin for q in p]) * M
        self._terms = {"hot": hot, "cold": hot + M * self.span, "delta": delta,
                       "upper": M - delta, "M": M, "energy": table["energy_over_kB"][:, runs],
                       "inv_heating": table["inv_centre_heating"][:, runs],
                       "inv_cooling": table["inv_centre_cooling"][:, runs]}

    def chunk(self, start, stop):
        """The :class:`FeedforwardChunk` of steps ``start`` ... ``stop - 1`` (in order)."""
        inputs, runs = self.inputs, self.runs
        rows, size = stop - start, inputs.size
        if runs.size == 0:
            return FeedforwardChunk(np.zeros((rows, size)), np.full((rows, size), np.nan),
                                    np.zeros((rows, size), dtype=bool), {})
        sensed, low, bad, exponent, energy = self._inverse(start, stop)
        values = (sensed - self.T_room) / self.gain
        diverged = {}
        if bad.any():
            for row, inverse in zip(*np.nonzero(bad)):
                message = (f"temperature-sensing inverse diverges at Lambda = "
                           f"{float(exponent[row, inverse])!r}: dH(f)/k_B = "
                           f"{float(energy[row, inverse])!r} K is too small for the hysteresis "
                           f"centre")
                for column in np.flatnonzero(self.of_run == inverse):
                    diverged.setdefault(int(runs[column]), message)
        shared = self.columns.size < runs.size          # some runs share an inverse
        filtered = self._filter(values[:, self.of_run] if shared else values)
        if runs.size == size and not shared:            # every run has its own compensator
            return FeedforwardChunk(filtered, sensed, low, diverged)
        expand = (lambda a: a[:, self.of_run]) if shared else (lambda a: a)  # noqa: E731
        P_ff = np.zeros((rows, size))
        T_ref = np.full((rows, size), np.nan)
        saturated = np.zeros((rows, size), dtype=bool)
        place = slice(0, runs.size) if self._leading else runs
        P_ff[:, place], T_ref[:, place], saturated[:, place] = filtered, expand(sensed), expand(low)
        return FeedforwardChunk(P_ff, T_ref, saturated, diverged)

    def _inverse(self, start, stop):
        """sense_temperature at R_ref(t_k) per inverse: (T_ref, saturated, diverged, Lambda, E)."""
        inputs, columns = self.inputs, self.columns
        if inputs.changes_within(start, stop):
            segments = inputs.segments(start, stop, columns)
        else:   # no load step inside: one row of terms, broadcast over the chunk
            segments = inputs.segments(start, start + 1, columns)
        segments = np.array(np.broadcast_to(segments, (segments.shape[0], columns.size)))
        segments[:, ~self.adaptive] = inputs.model_row
        index = segments * columns.size + np.arange(columns.size)
        take = lambda name: np.take(self._terms[name], index)  # noqa: E731
        heating = inputs.reference_heating_rows(start, stop, columns)
        reference = inputs.references(start, stop, columns)
        # mixed_fractions_of_resistance
        xi_mf = (reference - take("hot")) / self.span
        xi_p = (take("cold") - reference) / self.span
        # temperature_of_fractions: clamp into [delta, M - delta] and flag it
        delta, upper = take("delta"), take("upper")
        mf, p, clamped = clamp_fractions(xi_mf, xi_p, delta, upper)
        energy = take("energy")
        inverse = np.where(heating, take("inv_heating"), take("inv_cooling"))
        sensed, exponent, inverse_kelvin = temperature_of_fractions(mf, p, inverse, energy)
        out = {"T_ref": sensed, "saturated": clamped, "bad": ~(inverse_kelvin > 0.0),
               "exponent": exponent}
        if self.minor is not None:     # where a reversal is stored: the minor branch's inverse
            self.minor.invert({"xi_mf": xi_mf, "mf": mf, "p": p, "clamped": clamped,
                               "delta": delta, "upper": upper, "M": take("M"),
                               "energy": energy, "inverse": inverse, "heating": heating}, out)
        return (out["T_ref"], out["saturated"], out["bad"], out["exponent"],
                np.broadcast_to(energy, exponent.shape))

    def _filter(self, values):
        """Tustin filter y_k = b0 v_k + b1 v_(k-1) - a1 y_(k-1), row by row (steady start)."""
        out = np.empty_like(values)
        b0, b1, a1 = self.b0, self.b1, self.a1
        if self.previous_input is None:
            self.previous_input = values[0].copy()
            self.previous_output = values[0].copy()
        previous_input, previous_output = self.previous_input, self.previous_output
        work = np.empty(values.shape[1])
        for row in range(values.shape[0]):
            y = out[row]
            np.multiply(b0, values[row], out=y)
            np.multiply(b1, previous_input, out=work)
            np.add(y, work, out=y)
            np.multiply(a1, previous_output, out=work)
            np.subtract(y, work, out=y)
            previous_input, previous_output = values[row], y
        self.previous_input, self.previous_output = previous_input.copy(), previous_output.copy()
        return out
