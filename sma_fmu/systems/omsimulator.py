"""Run an SSP package in OMSimulator (OpenModelica's FMI/SSP simulator) as a separate process.

OMSimulator is on no package registry: build it from source (v3.0.0 was used,
docs/systems.md) and name the executable in :data:`ENVIRONMENT`. Nothing of the project
needs it; ``sma-fmu bench --only hosts`` adds it to the per-host table when the variable is set.

Its command line takes the step from the SSD's OpenModelica annotation
(``oms:FixedStepMaster``) but the stop time only from ``--stopTime`` (1 s otherwise: for
an SSP it does not read the DefaultExperiment). It writes every variable of every FMU, at
every step, into a MAT v4 result file (the CSV result has 12 digits only), which
:func:`read_mat_results` reads.
"""
import os
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from sma_fmu.runtime.scenario_signals import GRID_TOLERANCE

__all__ = ["ENVIRONMENT", "omsimulator_executable", "omsimulator_command", "read_mat_results",
           "run_ssp_omsimulator"]

ENVIRONMENT = "SMA_FMU_OMSIMULATOR"
RESULT_FILE = "omsimulator.mat"


def omsimulator_executable():
    """The OMSimulator executable named by :data:`ENVIRONMENT`, or None when it is unset."""
    value = os.environ.get(ENVIRONMENT)
    return Path(value) if value else None


def omsimulator_command(executable, ssp_path, stop_time_s, result_file=RESULT_FILE):
    """The command line that runs ``ssp_path`` from 0 to ``stop_time_s`` [s]."""
    return [str(executable), f"--stopTime={stop_time_s!r}", "--emitEvents=false",
            f"--resultFile={result_file}", str(ssp_path)]


def read_mat_results(path):
    """{variable name: values} of OMSimulator's MAT v4 result file (Dymola's layout:
    ``name`` and ``dataInfo`` stored transposed, ``data_2`` one row per variable)."""
    from scipy.io import loadmat

    mat = loadmat(str(path), chars_as_strings=False)
    chars = mat["name"]
    names = ["".join(chars[:, j]).rstrip("\x00 ") for j in range(chars.shape[1])]
    info, trajectories, constants = mat["dataInfo"], mat["data_2"], mat["data_1"]
    columns = {}
    for j, name in enumerate(names):
        matrix, index = int(info[0, j]), int(info[1, j])
        source = trajectories if matrix in (0, 2) else constants
        values = source[abs(index) - 1] * (1.0 if index > 0 else -1.0)
        columns[name] = values if matrix in (0, 2) else np.full(trajectories.shape[1], values[0])
    return columns


def run_ssp_omsimulator(ssp_path, step_size, steps, outputs, executable=None):
    """Run an SSP of :mod:`.ssp` in OMSimulator for ``steps`` steps of ``step_size`` [s].

    Returns {column: n + 1 samples at t_0 ... t_n} of ``outputs`` ({column: (component,
    variable)}) and the host's log lines, as (samples, log). OMSimulator couples by Jacobi.
    """
    from sma_fmu.systems.hosts import HostError

    executable = executable or omsimulator_executable()
    if executable is None:
        raise HostError(f"OMSimulator: set {ENVIRONMENT} to its executable")
    stop = steps * step_size
    with tempfile.TemporaryDirectory(prefix="sma_fmu_oms_") as folder:
        command = omsimulator_command(executable, Path(ssp_path).resolve(), stop)
        result = subprocess.run(command + [f"--tempDir={folder}"], cwd=folder,
                                capture_output=True, text=True, timeout=3600)
        log = (result.stdout + result.stderr).splitlines()
        mat = Path(folder) / RESULT_FILE
        if result.returncode != 0 or not mat.is_file():
            raise HostError(f"OMSimulator: {ssp_path}: exit status {result.returncode}: "
                            f"{' / '.join(line for line in log if 'error' in line.lower())}")
        columns = read_mat_results(mat)
    times = columns.pop("time")
    index = np.rint(times / step_size).astype(int)
    first = {}
    for row, k in enumerate(index):
        if abs(times[row] - k * step_size) <= GRID_TOLERANCE * step_size:
            first.setdefault(int(k), row)
    missing = [k for k in range(steps + 1) if k not in first]
    if missing:
        raise HostError(f"OMSimulator: {ssp_path}: no result at step {missing[0]} (t = "
                        f"{missing[0] * step_size!r} s)")
    rows = [first[k] for k in range(steps + 1)]
    samples = {}
    for column, (component, variable) in outputs.items():
        suffix = f".{component}.{variable}"
        found = [name for name in columns if name.endswith(suffix)]
        if len(found) != 1:
            raise HostError(f"OMSimulator: {ssp_path}: no result for {component}.{variable}")
        values = columns[found[0]][rows]
        samples[column] = values != 0 if column == "saturated" else values
    return samples, log
