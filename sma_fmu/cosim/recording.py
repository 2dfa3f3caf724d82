"""Record a run while it goes: the metrics from every step, the file and the figure from every k-th.

A :class:`RunRecorder` is the sink of :func:`sma_fmu.cosim.loop.run_loop`. It gets the rows
in blocks and passes each on at once:

- every row to :class:`~sma_fmu.cosim.metrics.StreamingMetrics` (metrics never depend on
  the output interval);
- every k-th row (k = ``output_interval_s`` / ``step_s``; row 0 and the final row always)
  to the time-series file, written block by block (:class:`TimeseriesWriter`: CSV or
  Parquet);
- the same rows to :class:`FigureSeries`, which keeps at most :data:`FIGURE_ROWS` of them,
  evenly spaced (it halves what it keeps when it fills), for the figures.

So the memory of a run does not grow with its length. :func:`read_timeseries` reads either
format back as a pandas DataFrame with the CSV's column names.
"""
import math
import sys
import time
from pathlib import Path

import numpy as np

from sma_fmu.cosim.loop import COLUMN_NAMES, COLUMNS, TIMESERIES_DTYPE
from sma_fmu.cosim.metrics import StreamingMetrics

__all__ = ["FORMATS", "FIGURE_ROWS", "CSV_FORMAT", "PARQUET_ROW_GROUP", "interval_steps", "TimeseriesWriter",
           "FigureSeries", "RunRecorder", "read_timeseries", "timeseries_name", "progress_bar"]

FORMATS = ("csv", "parquet")
FIGURE_ROWS = 20_000    # a figure keeps 20,000-40,000 rows (a 30-s run at 1 ms all 30,001)
CSV_FORMAT = "%.10g"    # the CSV's numbers: 10 significant digits (Parquet keeps every bit)
PARQUET_ROW_GROUP = 65_536  # rows per Parquet row group (8 MB in memory at most)
# Snappy: pyarrow's default codec, read by every Parquet reader (MATLAB's parquetread since
# R2019a, pandas, polars, DuckDB, Spark); 3x faster to write than zstd (30 s at 1 ms: 1.7 vs
# 4.8 ms), for a file 23 % larger (2.50 vs 2.03 MB)
PARQUET_CODEC = "snappy"
_FILE_NAMES = {"csv": "timeseries.csv", "parquet": "timeseries.parquet"}


def timeseries_name(fmt):
    """The time-series file name of format ``fmt`` (one of :data:`FORMATS`)."""
    if fmt not in _FILE_NAMES:
        raise ValueError(f"format must be one of {', '.join(FORMATS)}, got {fmt!r}")
    return _FILE_NAMES[fmt]


def interval_steps(output_interval_s, step_s, what="output interval"):
    """k: record every k-th step, for ``output_interval_s`` [s] (None: every step) and
    ``step_s`` [s]; the interval must be a whole number (>= 1) of steps, to 1e-9."""
    if output_interval_s is None:
        return 1
    if not (isinstance(output_interval_s, (int, float)) and math.isfinite(output_interval_s)
            and output_interval_s > 0.0):
        raise ValueError(f"{what} must be a number of seconds > 0, got {output_interval_s!r}")
    steps = output_interval_s / step_s
    k = round(steps)
    if k < 1 or abs(steps - k) > 1e-9 * max(1.0, steps):
        raise ValueError(f"{what} = {output_interval_s!r} s is not a whole number of steps of "
                         f"{step_s!r} s")
    return int(k)


class TimeseriesWriter:
    """Writes rows (structured arrays) to ``path`` block by block: CSV (a header of names
    with units, ``t_s,R_ref_ohm,...``) or Parquet (the same columns, every bit kept)."""

    def __init__(self, path, fmt="csv"):
        timeseries_name(fmt)
        self.path, self.fmt, self.rows = Path(path), fmt, 0
        self._stream = self._parquet = None
        self._pending, self._pending_rows = None, 0   # Parquet rows not yet written (a row group)
        self.external = False   # the CSV's rows are written by another program (hand_over)
        if fmt == "csv":
            self._stream = open(self.path, "w", encoding="utf-8", newline="\n")
            self._stream.write(",".join(COLUMN_NAMES) + "\n")

    def write(self, rows):
        """Append ``rows`` (a structured array with the fields of :data:`COLUMNS`)."""
        if rows.size == 0:
            return
        if self.external:   # written by the program it was handed over to: only counted
            pass
        elif self.fmt == "csv":
            # one %-format over the whole block (what np.savetxt does row by row): same text,
            # 1.5x faster (30,001 rows x 12 columns: 77 -> 51 ms)
            table = np.column_stack([rows[name].astype(float) for name, _ in COLUMNS])
            line = ",".join([CSV_FORMAT] * table.shape[1]) + "\n"
            self._stream.write((line * table.shape[0]) % tuple(table.ravel().tolist()))
        else:  # gathered into row groups of PARQUET_ROW_GROUP rows: they compress far better
            at = 0
            while at < rows.size:  # copied once, into the row group's own columns
                if self._pending is None:
                    self._pending = {name: np.empty(PARQUET_ROW_GROUP, dtype=rows.dtype[name])
                                     for name, _ in COLUMNS}
                    self._open()   # now, not at the first row group (a run's end, mostly)
                count = min(rows.size - at, PARQUET_ROW_GROUP - self._pending_rows)
                for name, column in self._pending.items():
                    column[self._pending_rows:self._pending_rows + count] = rows[name][at:at + count]
                self._pending_rows += count
                at += count
                if self._pending_rows == PARQUET_ROW_GROUP:
                    self._flush()
        self.rows += rows.size

    def hand_over(self):
        """Let another program append the CSV's rows (the C master writes them as this class
        would, byte for byte): the header is written and the file closed; :meth:`write` then
        only counts the rows. True if handed over (a CSV writer without rows yet)."""
        if self.fmt != "csv" or self.rows or self.external:
            return False
        self._stream.close()
        self._stream, self.external = None, True
        return True

    def _open(self):
        """The Parquet file, opened with the columns' schema (once)."""
        if self._parquet is not None:
            return
        import pyarrow as pa
        import pyarrow.parquet as pq

        empty = np.empty(0, dtype=TIMESERIES_DTYPE)
        schema = pa.Table.from_arrays([_arrow_column(empty[name]) for name, _ in COLUMNS],
                                      names=list(COLUMN_NAMES)).schema
        # no dictionary pages: float columns rarely repeat, and trying them took half the
        # write time (30 s at 1 ms: 22 -> 10 ms, the file 2.5 -> 2.0 MB)
        self._parquet = pq.ParquetWriter(str(self.path), schema, compression=PARQUET_CODEC,
                                         use_dictionary=False)

    def _flush(self):
        """Write the gathered rows as one Parquet row group (PARQUET_CODEC)."""
        import pyarrow as pa

        self._open()
        empty = np.empty(0, dtype=TIMESERIES_DTYPE)
        columns = [self._pending[name][:self._pending_rows] if self._pending is not None
                   else empty[name] for name, _ in COLUMNS]
        table = pa.Table.from_arrays([_arrow_column(column) for column in columns],
                                     names=list(COLUMN_NAMES))
        if self._pending_rows or self.rows == 0:
            self._parquet.write_table(table)
        del table                # the Arrow columns share the buffers, reused from here
        self._pending_rows = 0

    def close(self):
        """Finish the file (an empty run still gets its header or schema)."""
        if self._stream is not None or self.external:
            if self._stream is not None:
                self._stream.close()
            return
        if self._pending_rows or self._parquet is None:
            self._flush()
        self._parquet.close()
        self._parquet = None


def _joined(blocks):
    """The structured arrays ``blocks`` (one dtype) end to end: np.concatenate would first
    promote the structured dtype field by field, which cost as much as the copy itself."""
    dtype = blocks[0].dtype if blocks else TIMESERIES_DTYPE
    out = np.empty(sum(block.size for block in blocks), dtype=dtype)
    at = 0
    for block in blocks:
        out[at:at + block.size] = block
        at += block.size
    return out


def _arrow_column(values):
    """A float64 or bool numpy column as an Arrow array, built from its buffer: pa.array()
    and pa.table() import pandas to check their argument (about 45 MB of resident memory,
    a quarter of a run's), which nothing else of a run needs."""
    import pyarrow as pa

    if values.dtype == bool:
        bits = np.packbits(values, bitorder="little")   # Arrow's booleans: one bit each
        return pa.Array.from_buffers(pa.bool_(), len(values), [None, pa.py_buffer(bits)])
    data = np.ascontiguousarray(values, dtype=np.float64)
    return pa.Array.from_buffers(pa.float64(), len(values), [None, pa.py_buffer(data)])


class FigureSeries:
    """The rows a figure draws: every ``stride``-th recorded row, at most ``2 * limit`` kept
    between halvings; the last recorded row is always kept (the run's end). The kept rows
    are copied once, into a buffer of their own (:meth:`rows` gives it without a copy)."""

    def __init__(self, limit=FIGURE_ROWS):
        self.limit, self.stride, self.count = limit, 1, 0
        self._buffer, self._kept, self._last, self._given = None, 0, None, False

    def add(self, rows):
        """Offer recorded rows (consecutive, in order)."""
        if rows.size == 0:
            return
        chosen = rows[(-self.count) % self.stride::self.stride]  # ordinals % stride == 0
        self.count += rows.size
        self._last = rows[-1:].copy()
        need = self._kept + chosen.size
        if self._buffer is None or need > len(self._buffer) or self._given:
            # a larger buffer, or a fresh one after rows() gave this one away; the first is
            # large enough for loop-sized blocks (np.empty: pages are taken as they are used)
            capacity = max(need, 2 * self.limit + 4096,
                           0 if self._buffer is None else 2 * len(self._buffer))
            buffer = np.empty(capacity, dtype=rows.dtype)
            if self._kept:
                buffer[:self._kept] = self._buffer[:self._kept]
            self._buffer, self._given = buffer, False
        self._buffer[self._kept:need] = chosen
        self._kept = need
        if self._kept > 2 * self.limit:  # halve: keep every other kept row
            ordinals = np.arange(self._kept) * self.stride
            self.stride *= 2
            kept = self._buffer[:self._kept][ordinals % self.stride == 0]
            self._buffer[:kept.size] = kept
            self._kept = kept.size

    def rows(self):
        """The kept rows (a structured array), ending with the last row offered."""
        if self._last is None:
            return np.empty(0, dtype=TIMESERIES_DTYPE)
        kept = self._buffer[:self._kept]
        self._given = True
        if kept[-1]["t"] != self._last[0]["t"]:
            kept = _joined([kept, self._last])
        return kept


class RunRecorder:
    """The sink of one run: metrics from every row, the file and the figure every k-th row.

    ``folder``: where the time series goes (:func:`timeseries_name` of ``fmt``);
    ``every``: k (:func:`interval_steps`); ``progress``: a callable given the number of
    rows of each block, or None.
    """

    def __init__(self, scenario, folder, every=1, fmt="csv", progress=None):
        self.every, self.seen = every, 0
        self.seconds = 0.0                 # [s] spent recording (not running the model)
        self.metrics = StreamingMetrics(scenario)
        self.figure = FigureSeries()
        self.writer = TimeseriesWriter(Path(folder) / timeseries_name(fmt), fmt)
        self.last_row = scenario.steps     # index of the final row (always recorded)
        self.progress = progress

    def __call__(self, block):
        started = time.perf_counter()
        self.metrics.update(block)
        index = self.seen + np.arange(block.size)
        recorded = block if self.every == 1 else block[(index % self.every == 0) | (index == self.last_row)]
        self.writer.write(recorded)
        self.figure.add(recorded)
        self.seen += block.size
        if self.progress is not None:
            self.progress(block.size)
        self.seconds += time.perf_counter() - started

    def csv_for_host(self):
        """(path, every, last row) for a host that writes this run's CSV rows itself (the C
        master), with the file handed over to it (:meth:`TimeseriesWriter.hand_over`); None
        when the time series is Parquet or rows were recorded already. The recorder then
        counts the rows, the metrics and the figure as before."""
        if self.seen or not self.writer.hand_over():
            return None
        return self.writer.path, self.every, self.last_row

    def feed(self, data):
        """Record a whole series kept by a host (SSP, container) in loop-sized blocks."""
        from sma_fmu.cosim.loop import ROWS_PER_CHUNK

        for first in range(0, len(data), ROWS_PER_CHUNK):
            self(data[first:first + ROWS_PER_CHUNK])

    def close(self):
        """Finish the file; returns (metrics record, figure rows)."""
        self.writer.close()
        return self.metrics.result(), self.figure.rows()


def read_timeseries(path):
    """A run's time series (``timeseries.csv`` or ``timeseries.parquet``) as a pandas
    DataFrame with the columns ``t_s, R_ref_ohm, ...``."""
    import pandas as pd

    path = Path(path)
    if path.suffix == ".parquet":
        return pd.read_parquet(path)
    if path.suffix == ".csv":
        return pd.read_csv(path)
    raise ValueError(f"{path}: a time series is a .csv or .parquet file")


def progress_bar(total_rows, label, stream=None):
    """A bar over ``total_rows`` rows (:func:`sma_fmu.console.progress.bar`: on a terminal
    only, not with ``--quiet``), or None where none shows."""
    from sma_fmu.console import progress

    if not progress.enabled(stream):
        return None
    return progress.bar(total_rows, label, unit="step", stream=stream, unit_scale=True)
