"""N feedforward compensators (:class:`~sma_fmu.runtime.feedforward.FeedforwardStepper`) at once.

The compensator is open loop: its output at step k depends only on R_ref(t_k), f(t_k) and
its own memory (d_ref, the minor-loop reversal stack, the filter), never on the plant. So the
inverse of :mod:`~sma_fmu.runtime.sensing` (major branch of the reference direction, at the
measured or the fixed model load, with the saturation clamp; for ``inverse = "minor-loop"``
the branch of the compensator's own stack of reversal points, :mod:`.minor_loops`) is
computed for a whole chunk of steps in a few numpy calls, once per distinct compensator
(runs that differ only in gains or filter share it), and only the phase-lag filter
(Tustin, started in steady state) runs step by step, per run. The operations are those of
the scalar code, in its order; tests/studies/test_batch.py binds the two.

The inverses are columns, the major ones first and the minor-loop ones after them; each
kind is computed in its own contiguous arrays (numpy's loops over strided views are
several times slower), in place (``out=``) where it can.
"""
import numpy as np

from sma_fmu.runtime.phase_lag import tustin_coefficients
from sma_fmu.studies.batch.branches import two_stage_temperatures
from sma_fmu.studies.batch.minor_loops import (MinorLoopMemory, clamp_fractions,
                                               temperature_of_fractions)

__all__ = ["BatchFeedforward", "FeedforwardChunk", "STAGE_FIELDS"]

STAGE_FIELDS = ("M1", "M2", "energy2_heating", "energy2_cooling", "inv2_heating", "inv2_cooling")


class FeedforwardChunk:
    """Compensator outputs for steps ``start`` ... ``start + c - 1``, each (c, N).

    P_ff [W] (0 for "pi" runs), saturated (bool), T_ref [degC] (nan for "pi"; built when
    first read: the metrics do not need it); ``diverged``: {run: message} where the
    inverse has no temperature.
    """

    def __init__(self, P_ff, saturated, diverged, T_ref):
        self.P_ff, self.saturated, self.diverged = P_ff, saturated, diverged
        self._T_ref = T_ref          # an array, or a function that returns it

    @property
    def T_ref(self):
        """T_ref [degC] per step and run, (c, N)."""
        if callable(self._T_ref):
            self._T_ref = self._T_ref()
        return self._T_ref


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
        keys, chosen, wires = {}, [], {}
        key_of = [_inverse_key(scenarios[run], inputs.reference_group[run], wires)
                  for run in self.runs]
        for minor in (False, True):          # major inverses first, then the minor-loop ones
            for run, key in zip(self.runs, key_of):
                if (key[2] == "minor-loop") == minor and key not in keys:
                    keys[key] = len(keys)
                    chosen.append(run)
        self.of_run = np.array([keys[key] for key in key_of], dtype=int)  # column of each run
        self.columns = np.array(chosen, dtype=int)          # a run that stands for each inverse
        self._own = bool(np.array_equal(self.of_run, np.arange(self.runs.size)))  # one each
        self._tables([scenarios[run] for run in chosen])
        self.split = sum(1 for key in keys if key[2] != "minor-loop")   # first minor column
        minor = [scenarios[run].compensator_params for run in chosen[self.split:]]
        self.minor = (MinorLoopMemory([q.saturation_margin for q in minor],
                                      [q.memory_depth for q in minor],
                                      [q.terms.two_stage for q in minor]) if minor else None)
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
        self.T_max = column([q.T_max for q in p])
        self.gain = column([q.K_th for q in p])
        self.adaptive = np.array([s.controller.adapt_to_load for s in chosen], dtype=bool)
        M = table["M"][:, runs]
        hot = column([q.R_P for q in p]) + table["xi_F_min"][:, runs] * column(
            [q.R_F - q.R_P for q in p])
        delta = column([q.saturation_margin for q in p]) * M
        self._terms = {"hot": hot, "cold": hot + M * self.span, "delta": delta,
                       "upper": M - delta, "M": M,
                       "energy_heating": table["energy_over_kB"][:, runs],
                       "energy_cooling": table["energy_cooling"][:, runs],
                       "inv_heating": table["inv_centre_heating"][:, runs],
                       "inv_cooling": table["inv_centre_cooling"][:, runs]}
        for name in STAGE_FIELDS:               # the optional second stage (0: one stage)
            self._terms[name] = table[name][:, runs]
        self.two_stage = np.array([q.terms.two_stage for q in p], dtype=bool)

    def chunk(self, start, stop):
        """The :class:`FeedforwardChunk` of steps ``start`` ... ``stop - 1`` (in order)."""
        inputs, runs = self.inputs, self.runs
        rows, size = stop - start, inputs.size
        if runs.size == 0:
            return FeedforwardChunk(np.zeros((rows, size)), np.zeros((rows, size), dtype=bool),
                                    {}, lambda: np.full((rows, size), np.nan))
        values, low, sensed, failures = self._inverse(start, stop)
        diverged = {}
        for row, inverse, exponent, energy in failures:
            message = (f"temperature-sensing inverse diverges at Lambda = {exponent!r}: "
                       f"dH(f)/k_B = {energy!r} K is too small for the hysteresis centre")
            for column in np.flatnonzero(self.of_run == inverse):
                diverged.setdefault(int(runs[column]), message)
        expand = self._expander(rows)
        filtered = self._filter(expand(values))
        if runs.size == size:                           # every run has a compensator
            return FeedforwardChunk(filtered, expand(low), diverged, lambda: expand(sensed()))
        place = slice(0, runs.size) if self._leading else runs
        P_ff = np.zeros((rows, size))
        saturated = np.zeros((rows, size), dtype=bool)
        P_ff[:, place], saturated[:, place] = filtered, expand(low)

        def T_ref():
            out = np.full((rows, size), np.nan)
            out[:, place] = expand(sensed())
            return out
        return FeedforwardChunk(P_ff, saturated, diverged, T_ref)

    def _expander(self, rows):
        """(c, inverses) -> (c, feedforward runs): each run gets its inverse's column."""
        if self._own:
            return lambda a: a
        if self.columns.size == 1:           # one inverse for all: a broadcast view
            return lambda a: np.broadcast_to(a, (rows, self.runs.size))
        return lambda a: a[:, self.of_run]

    def _inverse(self, start, stop):
        """sense_temperature at R_ref(t_k) per inverse, (c, inverses) each: v = (T_ref -
        T_room)/K_th [W], saturated, T_ref [degC] (a function: built when asked for), and
        [(row, inverse, Lambda, dH/k_B [K])] where the inverse diverges.

        The major and the minor-loop columns are computed apart, each in contiguous arrays.
        """
        inputs, columns = self.inputs, self.columns
        if inputs.changes_within(start, stop):
            segments = inputs.segments(start, stop, columns)
        else:   # no load step inside: one row of terms, broadcast over the chunk
            segments = inputs.segments(start, start + 1, columns)
        segments = np.array(np.broadcast_to(segments, (segments.shape[0], columns.size)))
        segments[:, ~self.adaptive] = inputs.model_row
        index = segments * columns.size + np.arange(columns.size)
        values, saturated, sensed, failures = [], [], [], []
        for part, memory in ((slice(0, self.split), None),
                             (slice(self.split, columns.size), self.minor)):
            if part.stop == part.start:
                continue
            T_ref, low, bad, exponent, energy = self._part(start, stop, part, index[:, part],
                                                           memory)
            if bad.any():
                failures += [(row, part.start + column, float(exponent[row, column]),
                              float(energy[row, column])) for row, column in zip(*np.nonzero(bad))]
            over = T_ref > self.T_max[part]  # the demand bounded to validity.T_max, as
            if over.any():                    # FeedforwardStepper._demand does
                T_ref, low = np.where(over, self.T_max[part], T_ref), low | over
            values.append((T_ref - self.T_room[part]) / self.gain[part])
            saturated.append(low)
            sensed.append(T_ref)
        join = lambda arrays: (np.concatenate(arrays, axis=1)  # noqa: E731
                               if len(arrays) > 1 else arrays[0])
        return join(values), join(saturated), lambda: join(sensed), failures

    def _part(self, start, stop, part, index, memory):
        """(T_ref, saturated, bad, Lambda, E) of the inverse columns ``part`` (a slice);
        ``memory``: their :class:`MinorLoopMemory`, or None for the major inverse."""
        take = lambda name: np.take(self._terms[name], index)  # noqa: E731
        runs = self.columns[part]
        heating = self.inputs.reference_heating_rows(start, stop, runs)
        reference = self.inputs.references(start, stop, runs)
        span = self.span[part]
        # mixed_fractions_of_resistance
        xi_mf = np.subtract(reference, take("hot"))
        np.divide(xi_mf, span, out=xi_mf)
        xi_p = np.subtract(take("cold"), reference)
        np.divide(xi_p, span, out=xi_p)
        raw = (xi_mf.copy(), xi_p.copy()) if memory is not None else None
        # temperature_of_fractions: clamp into [delta, M - delta] and flag it
        delta, upper = take("delta"), take("upper")
        saturated = clamp_fractions(xi_mf, xi_p, delta, upper)
        energy = np.where(heating, take("energy_heating"), take("energy_cooling"))
        inverse = np.where(heating, take("inv_heating"), take("inv_cooling"))
        shape = xi_mf.shape
        sensed, exponent, bad = np.empty(shape), np.empty(shape), np.empty(shape, dtype=bool)
        two_stage = self.two_stage[part]
        stages = None
        if two_stage.any():
            stages = {"M1": take("M1"), "M2": take("M2"), "minus_energy": -energy,
                      "minus_energy2": -np.where(heating, take("energy2_heating"),
                                                 take("energy2_cooling")),
                      "inverse": inverse,
                      "inverse2": np.where(heating, take("inv2_heating"), take("inv2_cooling"))}
        if memory is None:
            temperature_of_fractions(xi_mf, xi_p, inverse, energy, sensed, exponent, bad)
            if stages is not None:
                two_stage_temperatures(xi_mf, xi_p, exponent, inverse, energy, stages,
                                       two_stage, sensed, bad)
        else:                          # the minor-loop inverse, with its reversal stacks
            stage = {"raw_mf": raw[0], "raw_p": raw[1], "mf": xi_mf, "p": xi_p,
                     "clamped": saturated.copy(), "delta": delta, "upper": upper,
                     "M": take("M"), "energy": energy, "inverse": inverse,
                     "heating": np.broadcast_to(heating, shape)}
            for name in ("energy_heating", "energy_cooling", "inv_heating", "inv_cooling",
                         *STAGE_FIELDS):
                stage[name] = take(name)
            memory.invert(stage, {"T_ref": sensed, "saturated": saturated, "bad": bad,
                                  "exponent": exponent})
        return sensed, saturated, bad, exponent, np.broadcast_to(energy, shape)

    def _filter(self, values):
        """Tustin filter y_k = b0 v_k + b1 v_(k-1) - a1 y_(k-1), row by row (steady start)."""
        out = np.empty(values.shape)
        b0, b1, a1 = self.b0, self.b1, self.a1
        if self.previous_input is None:
            self.previous_input = values[0].copy()
            self.previous_output = values[0].copy()
        previous_input, previous_output = self.previous_input, self.previous_output
        work = np.empty(values.shape[1])
        multiply, add, subtract = np.multiply, np.add, np.subtract
        for row in range(values.shape[0]):
            y, v = out[row], values[row]
            multiply(b0, v, y)
            multiply(b1, previous_input, work)
            add(y, work, y)
            multiply(a1, previous_output, work)
            subtract(y, work, y)
            previous_input, previous_output = v, y
        self.previous_input, self.previous_output = previous_input.copy(), previous_output.copy()
        return out
