"""Run the SSP packages and the container FMU in third-party hosts; results as loop time series.

- :func:`run_ssp_libcosim`: libcosim (Open Simulation Platform) through libcosimpy;
- :func:`run_ssp_ecos`: Ecos through ecospy (its library needs libtbb, from the ``tbb`` wheel);
- :func:`run_container_fmpy`, :func:`run_container_libcosim`: the container FMU alone;
- OMSimulator and fmpy's ``simulate_ssp``: :mod:`.omsimulator` (its samples in this form
  too) and :mod:`.fmpy_ssp` (the connectors it records).

Each takes the ``outputs`` the system has ({column: (component, variable)}, from
:func:`~sma_fmu.fmi.loop.wiring.loop_outputs`): a missing one is an error. Each returns their samples
at the communication points t_0 ... t_n (t_0: after initialization) as {column of
:data:`~sma_fmu.cosim.loop.COLUMNS`: array};
:func:`loop_series` turns them into the loop's time-series array, row k holding the
values at t_k and the outputs of step k, as the library loop does.
"""
import contextlib
import math
import os
import shutil
import tempfile

import numpy as np

from sma_fmu.cosim.loop import COLUMNS
from sma_fmu.files.archives import require_safe_archive
from sma_fmu.fmi.loop.wiring import loop_outputs
from sma_fmu.systems.libcosim_flags import file_observer, read_flags
from sma_fmu.systems.ssp import PARAMETER_SET

__all__ = ["HostError", "STATE_COLUMNS", "STEP_COLUMNS", "NO_COMPENSATOR", "loop_series",
           "run_ssp_libcosim", "run_ssp_ecos", "run_container_fmpy", "run_container_libcosim", "load_tbb"]

# columns whose value at t_k is the sample of row k (states and signals) ...
STATE_COLUMNS = ("R_ref", "R", "T", "x", "xi_P", "xi_M", "xi_F", "load")
# ... and columns whose row k is the block's output after step k (what acts over [t_k, t_k+1))
STEP_COLUMNS = ("P", "P_fb", "P_ff", "T_ref", "saturated")
# the columns of a block the loop lacks (the "pi" controller's compensator), as the library
# loop's rows hold them: u_ff = 0 W, T_ref = nan, not saturated
NO_COMPENSATOR = {"P_ff": 0.0, "T_ref": math.nan, "saturated": False}


class HostError(RuntimeError):
    """A host failed to load or to run a system; the message names the host and the file."""


def loop_series(scenario, samples, steps):
    """The loop's time-series array from host ``samples`` ({column: n + 1 values}).

    Columns the loop lacks (not in :func:`~sma_fmu.fmi.loop.wiring.loop_outputs`: the compensator's,
    for the "pi" controller) get the values the library loop writes; the last row has no
    step outputs (nan), as there.
    """
    present = loop_outputs(scenario.controller.feedforward)
    dtype = [(name, bool if name == "saturated" else float) for name, _ in COLUMNS]
    data = np.zeros(steps + 1, dtype=dtype)
    data["t"] = np.arange(steps + 1) * scenario.step_s
    for name in STATE_COLUMNS:
        data[name] = samples[name]
    for name in STEP_COLUMNS:
        if name in present:
            data[name][:-1] = np.asarray(samples[name])[1:]
        else:
            data[name][:-1] = NO_COMPENSATOR[name]
        data[name][-1] = False if name == "saturated" else math.nan
    data["stroke"] = data["x"][0] - data["x"]
    return data


# --------------------------------------------------------------------------- libcosim
def _libcosim_run(load, observed, steps, what):
    """Step the libcosim execution ``load()`` makes; returns {column: n + 1 samples} of ``observed``.

    ``observed`` maps columns to (slave name, variable name); Reals are recorded by a
    time-series observer (which keeps the sample after initialization), Booleans by a file
    observer that logs them alone (:mod:`.libcosim_flags`) into a folder of ours, removed
    when the run ends, and read once the execution is gone.
    """
    with tempfile.TemporaryDirectory(prefix="sma-fmu-libcosim-", ignore_cleanup_errors=True) as folder:
        samples, flags = _libcosim_steps(load, observed, steps, what, folder)
        try:
            samples.update(read_flags(folder, flags, steps, what))
        except ValueError as error:
            raise HostError(str(error)) from None
    return samples


def _libcosim_steps(load, observed, steps, what, folder):
    """Run ``steps`` steps; returns ({column: Real samples}, {column: (slave, Boolean)}).

    The execution and the file observer live in this function only, so both are gone (and
    libcosim has closed its files) when it returns or raises.
    """
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimObserver import CosimObserver

    execution = log = None
    try:
        execution = load()
        slaves = {info.name.decode(): info.index for info in execution.slave_infos()}
        variables = {(name, v.name.decode()): v for name, index in slaves.items()
                     for v in execution.slave_variables(index)}
        missing = [key for key in observed.values() if key not in variables]
        if missing:
            raise HostError(f"libcosim: {what} has no variable {missing[0][0]}.{missing[0][1]}")
        flags = {column: key for column, key in observed.items()
                 if variables[key].type == CosimVariableType.BOOLEAN.value}
        reals = {column: (slaves[key[0]], variables[key].reference)
                 for column, key in observed.items() if column not in flags}
        series = CosimObserver.create_time_series(buffer_size=steps + 1)
        execution.add_observer(series)
        for index, reference in reals.values():
            series.start_time_series(index, reference, CosimVariableType.REAL)
        if flags:
            log = file_observer(folder, flags)
            execution.add_observer(log)
        if not execution.step(steps):
            stopped = execution.status().current_time * 1e-9
            raise HostError(f"libcosim: {what}: the run failed at t = {stopped:g} s; see its log")
        return {column: _libcosim_samples(series, index, reference, steps)
                for column, (index, reference) in reals.items()}, flags
    finally:
        del execution, log  # even when an error's traceback keeps this frame


def _libcosim_samples(series, index, reference, steps):
    # libcosimpy counts a sample of step number 0 as missing: read step 0 on its own
    first = series.time_series_real_samples(index, reference, from_step=0, sample_count=2)[2]
    rest = series.time_series_real_samples(index, reference, from_step=1, sample_count=steps)[2]
    values = np.array(first[:1] + list(rest))
    if values.size != steps + 1:
        raise HostError(f"libcosim recorded {values.size} samples, expected {steps + 1}")
    return values


def _quiet_libcosim():
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level

    log_output_level(CosimLogLevel.WARNING)


def run_ssp_libcosim(ssp_path, steps, outputs):
    """Run an SSP of :mod:`.ssp` for ``steps`` steps in libcosim; returns {column: samples}.

    The step size comes from the SSD's OSP annotation. libcosim couples by Jacobi.
    """
    require_safe_archive(ssp_path)
    from libcosimpy.CosimExecution import CosimExecution

    _quiet_libcosim()

    def load():
        try:
            return CosimExecution.from_ssp_file(str(ssp_path))
        except AssertionError:
            raise HostError(f"libcosim cannot load {ssp_path}; see its log") from None
    return _libcosim_run(load, outputs, steps, str(ssp_path))


def run_container_libcosim(fmu_path, step_size, steps, outputs):
    """Run the container FMU alone in libcosim, ``steps`` steps of ``step_size`` [s]."""
    require_safe_archive(fmu_path)
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimSlave import CosimLocalSlave

    _quiet_libcosim()

    def load():  # the execution owns the slave once added
        execution = CosimExecution.from_step_size(step_size=int(round(step_size * 1e9)))
        slave = CosimLocalSlave(fmu_path=str(fmu_path), instance_name="loop")
        if execution.add_local_slave(local_slave=slave) < 0:
            raise HostError(f"libcosim cannot load {fmu_path}; see its log")
        return execution
    observed = {column: ("loop", column) for column in outputs}
    return _libcosim_run(load, observed, steps, str(fmu_path))


# ------------------------------------------------------------------------------- Ecos
def load_tbb():
    """Load libtbb.so.12 from the ``tbb`` wheel (Ecos's library needs it) before ecospy."""
    import ctypes
    from importlib.metadata import PackageNotFoundError, files

    try:
        candidates = [f.locate() for f in files("tbb") or () if f.name == "libtbb.so.12"]
    except PackageNotFoundError:
        candidates = []
    for path in candidates:
        ctypes.CDLL(str(path), mode=ctypes.RTLD_GLOBAL)
        return path
    raise HostError("Ecos needs libtbb.so.12: pip install tbb (or install Debian's libtbb12)")


def run_ssp_ecos(ssp_path, step_size, steps, outputs):
    """Run an SSP of :mod:`.ssp` in Ecos, ``steps`` steps of ``step_size`` [s] (Jacobi)."""
    require_safe_archive(ssp_path)
    load_tbb()
    from ecospy import EcosLib, EcosSimulation

    EcosLib.set_log_level("warn")
    samples = {column: [] for column in outputs}
    try:
        with _ecos_unpack_folder() as unpacked, EcosSimulation(
                ssp_path=str(ssp_path), step_size=step_size) as simulation:
            unpacked()
            simulation.init(parameter_set=PARAMETER_SET)  # without the name Ecos binds nothing
            readers = _ecos_readers(simulation, outputs, ssp_path)
            for k in range(steps + 1):
                if k:
                    simulation.step()
                for column, read in readers.items():
                    samples[column].append(read())
            simulation.terminate()
    except Exception as error:  # ecospy raises bare Exception with Ecos's message
        if isinstance(error, HostError):
            raise
        raise HostError(f"Ecos: {ssp_path}: {error}") from None
    return {column: np.array(values) for column, values in samples.items()}


@contextlib.contextmanager
def _ecos_unpack_folder():
    """A folder of our own for the copy of the SSP Ecos unpacks, removed when the run ends.

    Ecos unpacks an SSP into ``ecos_ssp_<uuid>`` under the system's temporary folder
    (``TMPDIR``) and never removes it: 2.9 MB left behind per run. So ``TMPDIR`` names a
    folder of ours while Ecos opens the SSP (call the yielded function once it has), and
    that folder goes, with Ecos's copy, after the simulation is closed."""
    folder = tempfile.mkdtemp(prefix="sma-fmu-ecos-")
    before = os.environ.get("TMPDIR")
    os.environ["TMPDIR"] = folder

    def restore():
        if before is None:
            os.environ.pop("TMPDIR", None)
        else:
            os.environ["TMPDIR"] = before
    try:
        yield restore
    finally:
        restore()
        shutil.rmtree(folder, ignore_errors=True)


def _ecos_readers(simulation, outputs, ssp_path):
    """{column: function reading its value now}; a variable Ecos cannot read is an error."""
    readers = {}
    for column, (component, variable) in outputs.items():
        name = f"{component}::{variable}"
        read = simulation.get_bool if column == "saturated" else simulation.get_real
        try:
            read(name)
        except Exception as error:  # noqa: BLE001 - ecospy raises bare Exception
            raise HostError(f"Ecos: {ssp_path}: cannot read {name}: {error}") from None
        readers[column] = (lambda read=read, name=name: read(name))
    return readers


# ------------------------------------------------------------------------------ fmpy
def run_container_fmpy(fmu_path, step_size, steps, outputs):
    """Run the container FMU in fmpy's ``simulate_fmu``; returns {column: samples}."""
    require_safe_archive(fmu_path)
    from fmpy import read_model_description, simulate_fmu

    names = {v.name for v in read_model_description(str(fmu_path)).modelVariables
             if v.causality == "output"}
    missing = [column for column in outputs if column not in names]
    if missing:
        raise HostError(f"fmpy: {fmu_path} has no output {missing[0]}")
    result = simulate_fmu(str(fmu_path), stop_time=steps * step_size, step_size=step_size,
                          output_interval=step_size, output=list(outputs))
    if result.size != steps + 1:
        raise HostError(f"fmpy: {fmu_path}: the run stopped after {result.size - 1} of {steps} steps")
    return {column: result[column] for column in outputs}
