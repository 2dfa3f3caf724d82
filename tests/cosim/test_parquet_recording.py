"""The Parquet time series: every bit and every Boolean back, written without importing pandas.

pyarrow's ``pa.array``/``pa.table`` import pandas to check their argument, about 45 MB of
resident memory that a run does not otherwise need (a one-hour run's peak RSS has to stay
under 200 MB, issue 41); the writer builds its columns from their buffers instead.
"""
import subprocess
import sys

import numpy as np
import pytest

from sma_fmu.cosim.loop import COLUMNS, TIMESERIES_DTYPE
from sma_fmu.cosim.recording import TimeseriesWriter, read_timeseries


@pytest.mark.parametrize("rows", [0, 1, 9, 70_001])
def test_parquet_gives_back_every_value(tmp_path, rows):
    rng = np.random.default_rng(rows)
    data = np.zeros(rows, dtype=TIMESERIES_DTYPE)
    for name, _ in COLUMNS:
        data[name] = rng.random(rows) > 0.5 if name == "saturated" else rng.normal(size=rows)
    if rows > 3:
        data["P"][2] = np.nan
    writer = TimeseriesWriter(tmp_path / "timeseries.parquet", "parquet")
    for first in range(0, rows, 4096):
        writer.write(data[first:first + 4096])
    writer.close()
    frame = read_timeseries(tmp_path / "timeseries.parquet")
    assert len(frame) == rows and str(frame.dtypes.iloc[-1]) == "bool"
    for index, (name, _) in enumerate(COLUMNS):
        assert np.array_equal(frame.iloc[:, index].to_numpy(), data[name],
                              equal_nan=data[name].dtype != bool), name


def test_a_parquet_recording_does_not_import_pandas(tmp_path):
    script = (
        "import sys\n"
        "from sma_fmu.cosim.loop import run_library\n"
        "from sma_fmu.cosim.recording import RunRecorder\n"
        "from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios\n"
        "import dataclasses\n"
        "s = load_scenario(resolve_scenarios(['heavy-pi'])[0])\n"
        "s = dataclasses.replace(s, stop_time_s=1.0)\n"
        f"r = RunRecorder(s, {str(tmp_path)!r}, 1, 'parquet')\n"
        "run_library(s, sink=r)\n"
        "r.close()\n"
        "print('pandas' in sys.modules, 'pyarrow' in sys.modules)\n")
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                            check=True)
    assert result.stdout.split() == ["False", "True"]
    assert (tmp_path / "timeseries.parquet").stat().st_size > 0
