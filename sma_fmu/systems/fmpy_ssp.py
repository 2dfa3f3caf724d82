"""Run an SSP package in fmpy's ``simulate_ssp`` and line its results up with the library loop.

What fmpy 0.3.32's ``simulate_ssp`` does (``fmpy/ssp/simulation.py``):

- it applies **no** parameter binding of the SSD (only a ``parameter_set`` passed to it,
  and no String in it), and reads no DefaultExperiment or annotation: the caller gives the
  stop time and step. Each FMU runs with its defaults, which in our packed FMUs are the
  scenario's values (:mod:`.packed`);
- it couples by Jacobi: every FMU steps with the outputs the others had after the step
  before, passed along the connections after all have stepped;
- before the first step every connector holds **0.0**, not the outputs after
  initialization: at t = 0 every input is 0. The compensator takes R_ref = 0 ohm as no
  reference yet (P_ff = 0 W, saturated, one warning; :mod:`sma_fmu.runtime.feedforward`),
  the PI sees R = R_ref = 0 ohm and the plant P_in = 0 W and load = 0 kg. So every loop
  runs, and differs from the library's Jacobi loop by that first step (the compensator's
  filter then starts at the second sample, the PI's integral and the plant carry the
  first step on);
- it adds up its time (t + h + h + ...) and records only the connectors, after each step.

:func:`run_ssp_fmpy` runs it; :func:`fmpy_ssp_series` takes the columns of the loop it
records, aligned with the rows of the library loop.
"""
import numpy as np

__all__ = ["run_ssp_fmpy", "fmpy_ssp_series", "fmpy_ssp_deviation", "FMPY_SSP_COLUMNS"]

# loop column -> the connector fmpy records, and whether it is a state (value at t_k+1 after
# step k) or a step output (the block's output of step k)
FMPY_SSP_COLUMNS = {"R_ref": ("signals.R_ref", "state"), "load": ("signals.load", "state"),
                    "R": ("plant.R", "state"), "P_ff": ("compensator.P_ff", "step")}


def run_ssp_fmpy(ssp_path, step_size, steps):
    """The structured array of ``simulate_ssp`` for ``steps`` steps of ``step_size`` [s].

    Row k: the time t_k and every connector's value after step k. Raises
    :class:`~.hosts.HostError` naming fmpy when the run stops early.
    """
    from fmpy.ssp.simulation import simulate_ssp

    from sma_fmu.systems.hosts import HostError

    try:
        result = simulate_ssp(str(ssp_path), stop_time=steps * step_size, step_size=step_size)
    except Exception as error:  # noqa: BLE001 - fmpy raises bare Exceptions
        raise HostError(f"fmpy simulate_ssp: {ssp_path}: {error}") from None
    if result.size < steps:
        raise HostError(f"fmpy simulate_ssp: {ssp_path}: {result.size} of {steps} steps")
    return result[:steps]  # its sum of steps may fall short of the stop time: one more step


def fmpy_ssp_series(result):
    """{column: values} of a :func:`run_ssp_fmpy` result, each aligned with rows of the library
    loop: states (R_ref, load, R) at t_1 ... t_n, the library's rows 1 ... n; step outputs
    (P_ff, and P, the power the plant applied) of steps 0 ... n-1, its rows 0 ... n-1.

    P: the plant's P_in held over step k is what its connector got after step k - 1 (0 W
    before the first step), applied as max(0, P_in).
    """
    names = result.dtype.names
    series = {column: np.asarray(result[connector], dtype=float)
              for column, (connector, _) in FMPY_SSP_COLUMNS.items() if connector in names}
    power = np.concatenate(([0.0], np.asarray(result["plant.P_in"], dtype=float)[:-1]))
    series["P"] = np.maximum(0.0, power)
    return series


def fmpy_ssp_deviation(series, library):
    """Largest |difference| of :func:`fmpy_ssp_series` from the library loop's array."""
    largest = 0.0
    for column, values in series.items():
        kind = FMPY_SSP_COLUMNS.get(column, (None, "step"))[1]
        reference = library[column][1:] if kind == "state" else library[column][:-1]
        largest = max(largest, float(np.max(np.abs(values - reference))))
    return largest
