"""The C master's samples as the loop's rows.

The host sends the recorded outputs at t_0 (after initialization) ... t_n (after each
step); row k of the loop holds the states and signals at t_k and the blocks' outputs of
step k, which the host reads after that step (sample k + 1), as :func:`~.hosts.loop_series`
does for a whole series. :class:`RowAssembler` does it frame by frame, with the numbers
the fmpy master's :func:`~sma_fmu.cosim.loop.run_loop` computes in Python (t_k = k h, the
stroke x_0 - x_k), and hands the rows on in its blocks of
:data:`~sma_fmu.cosim.loop.ROWS_PER_CHUNK` (the streaming metrics add per block: the same
blocks give the same sums, to the bit). The host's first frame has one sample more, so
each frame makes one such block, handed on without a copy. A column the host does not
record (a sink that reads only some, :func:`recorded_columns`) is NaN in every row (False
for ``saturated``).
"""
import math

import numpy as np

from sma_fmu.cosim.loop import COLUMNS, ROWS_PER_CHUNK, TIMESERIES_DTYPE
from sma_fmu.systems.hosts import NO_COMPENSATOR, STATE_COLUMNS, STEP_COLUMNS

__all__ = ["recorded_columns", "csv_columns", "RowAssembler"]


def recorded_columns(system, read=None):
    """The columns the host records for ``system``, in the order of its samples: grouped by
    component (the host reads neighbouring columns of one component in one call). ``read``:
    the loop's columns the sink reads (None: all); only those are recorded (``x`` for the
    stroke)."""
    outputs = system.outputs
    wanted = outputs if read is None else [c for c in outputs if c in read or (c == "x" and "stroke" in read)]
    return sorted(wanted, key=lambda column: (outputs[column][0], column == "saturated"))


def csv_columns(columns):
    """The loop host's words for the CSV's columns (:data:`~sma_fmu.cosim.loop.COLUMNS`, its
    "csv" line) from the recorded ``columns``: the rows :class:`RowAssembler` makes, as text."""
    index = {name: i for i, name in enumerate(columns)}
    words = []
    for name, _ in COLUMNS:
        if name == "t":
            words.append("t")
        elif name == "stroke":
            words.append(f"x:{index['x']}")
        elif name in STATE_COLUMNS:
            words.append(f"s:{index[name]}")
        elif name not in index:   # a block the loop lacks (NO_COMPENSATOR): after each step
            value = float(NO_COMPENSATOR[name])   # (the final row: nan, or False)
            kind = "c" if name == "saturated" else "k"
            words.append(f"{kind}:{'nan' if math.isnan(value) else repr(value)}")
        else:
            words.append(f"{'b' if name == 'saturated' else 'a'}:{index[name]}")
    return " ".join(words)


class RowAssembler:
    """Samples (raw doubles, ``columns`` per sample) in, the loop's rows out, to ``sink``
    (a callable taking structured arrays) or kept (``sink`` None)."""

    def __init__(self, scenario, columns, sink=None, missing=()):
        self.step_s, self.sink = scenario.step_s, sink
        self.missing = set(missing)   # loop columns not recorded: NaN (False) in every row
        self.index = {name: i for i, name in enumerate(columns)}
        self.width = len(columns)
        self.count = 0                  # rows made so far
        self._carry = self._start_x = None
        self._out = np.empty(ROWS_PER_CHUNK, dtype=TIMESERIES_DTYPE)
        self._filled, self._kept = 0, []

    def add(self, payload):
        """Take one frame of samples (bytes)."""
        samples = np.frombuffer(payload, dtype=np.float64).reshape(-1, self.width)
        if len(samples) == 0:
            return
        first = self._carry   # the sample before this frame (its row waited for this one)
        if first is None and "x" in self.index:
            self._start_x = samples[0, self.index["x"]]
        self._carry = samples[-1].copy()
        if first is None:
            if len(samples) > 1:
                self._rows(None, samples[:-1], samples[1:])
        else:
            self._rows(first, samples[:-1], samples)

    def _rows(self, first, now, after):
        """Rows from the sample ``first`` (None: no such row) and the samples ``now``, and the
        samples after their step, one for each row (``after`` None: no step)."""
        lead = 0 if first is None else 1
        size = lead + len(now)
        block = np.empty(size, dtype=TIMESERIES_DTYPE)
        block["t"] = np.arange(self.count, self.count + size, dtype=np.float64) * self.step_s
        for name in STATE_COLUMNS:
            column, index = block[name], self.index.get(name)
            if index is None:   # not recorded
                column[:] = math.nan
                continue
            if lead:
                column[0] = first[index]
            column[lead:] = now[:, index]
        block["stroke"] = math.nan if self._start_x is None else self._start_x - block["x"]
        for name in STEP_COLUMNS:
            if name in self.missing:
                block[name] = False if name == "saturated" else math.nan
            elif after is None:
                block[name] = False if name == "saturated" else math.nan
            elif name not in self.index:
                block[name] = NO_COMPENSATOR[name]
            elif name == "saturated":
                block[name] = after[:, self.index[name]] != 0.0
            else:
                block[name] = after[:, self.index[name]]
        self.count += size
        self._emit(block)

    def _emit(self, block):
        if self._filled == 0 and len(block) == ROWS_PER_CHUNK:  # a whole block: no copy
            self._send(block)
            return
        first = 0
        while first < len(block):
            take = min(ROWS_PER_CHUNK - self._filled, len(block) - first)
            self._out[self._filled:self._filled + take] = block[first:first + take]
            self._filled += take
            first += take
            if self._filled == ROWS_PER_CHUNK:
                self._send()

    def _send(self, block=None):
        """Hand on ``block`` (one of its own), else the gathered rows."""
        if block is None:
            block, self._filled = self._out[:self._filled], 0
            self._out = np.empty(ROWS_PER_CHUNK, dtype=TIMESERIES_DTYPE)  # the sink may keep it
        if self.sink is None:
            self._kept.append(block)
        else:
            self.sink(block)

    @property
    def started(self):
        """Whether a sample came (the time reached is then ``count`` steps)."""
        return self._carry is not None

    def finish(self):
        """The last sample as the final row (no step outputs), the rows not yet sent; returns
        every row (a structured array) when there is no sink, else None."""
        if self._carry is not None:
            self._rows(self._carry, self._carry[:0].reshape(0, self.width), None)
            self._carry = None
        if self._filled:
            self._send()
        if self.sink is not None:
            return None
        return (np.concatenate(self._kept) if self._kept
                else np.empty(0, dtype=TIMESERIES_DTYPE))
