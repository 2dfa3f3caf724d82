"""Each host's run of a scenario against the library loop of the host's coupling.

:func:`compare_hosts` runs a scenario on the library path (Gauss-Seidel and Jacobi) and
in the hosts of :data:`~.runs.HOSTS`, and reports per run the RMSE of R - R_ref (the
metric of :mod:`sma_fmu.cosim.metrics`) and the largest deviation of any time-series
column from the library run of the same coupling. The host "fmpy-ssp" is fmpy's
``simulate_ssp``, which records only the connectors (:mod:`.fmpy_ssp`): its deviation
covers R_ref, load, R, P and P_ff, its RMSE R - R_ref; a loop it cannot run gets a row
with a ``note`` and no numbers. :func:`rmse_table` and :func:`host_table` format the rows
(``sma-fmu bench --only hosts`` prints them; docs/systems.md shows them).
"""
import math
import tempfile
import time

import numpy as np

from sma_fmu.cosim.loop import COLUMNS, COUPLINGS, run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.systems.closed_loop import closed_loop
from sma_fmu.systems.fmpy_ssp import fmpy_ssp_deviation, fmpy_ssp_series, run_ssp_fmpy
from sma_fmu.systems.hosts import HostError
from sma_fmu.systems.runs import DEFAULT_HOSTS, HOSTS, run_host, write_artifact

__all__ = ["deviation", "compare_hosts", "rmse_table", "host_table", "FMPY_SSP"]

FMPY_SSP = "fmpy-ssp"  # fmpy's simulate_ssp: the SSP, Jacobi, its connectors only


def deviation(data, reference):
    """Largest |difference| over every numeric column of two time-series arrays (nan = nan)."""
    largest = 0.0
    for name, _ in COLUMNS:
        a, b = data[name].astype(float), reference[name].astype(float)
        same_nan = np.isnan(a) & np.isnan(b)
        if np.any(np.isnan(a) != np.isnan(b)):
            return math.inf
        if np.any(~same_nan):
            largest = max(largest, float(np.max(np.abs(a[~same_nan] - b[~same_nan]))))
    return largest


def _rmse(data, scenario):
    return scenario_metrics(data, scenario)["overall"]["rmse_ohm"]


def _fmpy_ssp_row(scenario, ssp_path, library):
    """The row of fmpy's simulate_ssp: its recorded columns against the library's Jacobi loop."""
    row = {"scenario": scenario.name, "run": "fmpy simulate_ssp (ssp)", "coupling": "jacobi"}
    start = time.perf_counter()
    try:
        series = fmpy_ssp_series(run_ssp_fmpy(ssp_path, scenario.step_s, scenario.steps))
    except HostError as error:
        return {**row, "rmse_ohm": None, "deviation": None, "wall_time_s": time.perf_counter() - start,
                "note": str(error).replace(f"fmpy simulate_ssp: {ssp_path}: ", "")}
    data = library.data.copy()  # the library's row 0, then what fmpy recorded at t_1 ... t_n
    data["R_ref"][1:], data["R"][1:] = series["R_ref"], series["R"]
    return {**row, "rmse_ohm": _rmse(data, scenario),
            "deviation": fmpy_ssp_deviation(series, library.data),
            "wall_time_s": time.perf_counter() - start}


def compare_hosts(scenario, fmu_dir, hosts=DEFAULT_HOSTS, artifacts=None):
    """Rows {scenario, run, coupling, rmse_ohm, deviation, wall_time_s} for ``scenario``.

    ``hosts``: keys of :data:`~.runs.HOSTS` (default :data:`~.runs.DEFAULT_HOSTS`; add
    "omsimulator" when SMA_FMU_OMSIMULATOR names its executable) or :data:`FMPY_SSP`.

    ``artifacts``: optional {"ssp": path, "container": path} already written for the
    scenario; a kind the ``hosts`` need and that is not given is built once, from the FMUs
    in ``fmu_dir`` into a temporary folder, and run by each of its hosts. A host row's
    ``wall_time_s`` is its run alone, without the build. ``deviation`` is the largest
    difference from the library run of the same coupling (0 for the library rows).
    """
    artifacts = dict(artifacts or {})
    library = {coupling: run_library(scenario, coupling) for coupling in COUPLINGS}
    rows = [{"scenario": scenario.name, "run": "library", "coupling": coupling,
             "rmse_ohm": _rmse(result.data, scenario), "deviation": 0.0,
             "wall_time_s": result.wall_time_s}
            for coupling, result in library.items()]
    missing = sorted({"ssp" if host == FMPY_SSP else HOSTS[host][0] for host in hosts}
                     - set(artifacts))
    with tempfile.TemporaryDirectory(prefix="sma_fmu_compare_") as folder:
        if missing:
            system = closed_loop(scenario, fmu_dir)
            artifacts.update({kind: write_artifact(kind, system, folder) for kind in missing})
        for host in hosts:
            if host == FMPY_SSP:
                rows.append(_fmpy_ssp_row(scenario, artifacts["ssp"], library["jacobi"]))
                continue
            kind, coupling, _ = HOSTS[host]
            result = run_host(host, scenario, fmu_dir, artifacts[kind])
            rows.append({"scenario": scenario.name, "run": f"{host} ({kind})",
                         "coupling": coupling, "rmse_ohm": _rmse(result.data, scenario),
                         "deviation": deviation(result.data, library[coupling].data),
                         "wall_time_s": result.wall_time_s})
    return rows


def _table_frame(rows):
    """(runs, scenarios, {(scenario, run, coupling): row}, the Markdown head) of host rows."""
    runs = list(dict.fromkeys((row["run"], row["coupling"]) for row in rows))
    scenarios = list(dict.fromkeys(row["scenario"] for row in rows))
    value = {(row["scenario"], row["run"], row["coupling"]): row for row in rows}
    lines = ["| scenario | " + " | ".join(f"{run}, {coupling}" for run, coupling in runs) + " |",
             "|---|" + "---:|" * len(runs)]
    return runs, scenarios, value, lines


def rmse_table(rows):
    """Markdown: one line per scenario, one column per run (RMSE [ohm], coupling in the head)."""
    runs, scenarios, value, lines = _table_frame(rows)
    for name in scenarios:
        cells = [_number(value.get((name, *run), {}).get("rmse_ohm"), ".3f") for run in runs]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    worst = max((row["deviation"] for row in rows if row["deviation"] is not None), default=0.0)
    lines += ["", f"Largest deviation of a host run from the library run of its coupling, over "
                  f"all time-series columns: {worst:.2g}"]
    return "\n".join(lines)


def _number(value, spec):
    return "–" if value is None else format(value, spec)


def host_table(rows):
    """Markdown: one line per scenario, one column per run, each cell "RMSE [ohm] / largest
    deviation from the library run of its coupling" ("–" where a host cannot run it)."""
    runs, scenarios, value, lines = _table_frame(rows)
    for name in scenarios:
        cells = []
        for run in runs:
            row = value.get((name, *run))
            if row is None or row["rmse_ohm"] is None:
                cells.append("–")
            elif row["run"] == "library":
                cells.append(f"{row['rmse_ohm']:.3f}")
            else:
                cells.append(f"{row['rmse_ohm']:.3f} / {row['deviation']:.1e}")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    notes = sorted({f"{row['run']}: {row['note']}" for row in rows if row.get("note")})
    return "\n".join(lines + ([""] + notes if notes else []))
