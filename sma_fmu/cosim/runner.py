"""Run scenarios and write their results: CSV, metrics JSON, figures, comparison table.

For each scenario ``NAME`` in ``out_dir``: ``NAME/timeseries.csv``, ``NAME/metrics.json``
and ``NAME/figure.png``. For each group of scenarios that differ only in the controller:
``comparison-GROUP.png``. Over the whole run: ``comparison.md``, which ranks the
controllers by RMSE in each group, and ``summary.json``.
"""
import time

import numpy as np

from sma_fmu.cosim.loop import COLUMNS, run_library
from sma_fmu.fmi.build import DEFAULT_FMU_DIR
from sma_fmu.cosim.master import run_fmus
from sma_fmu.cosim.metrics import METRIC_START_S, scenario_metrics
from sma_fmu.cosim.plots import plot_comparison, plot_run
from sma_fmu.cosim.scenario import CONTROLLERS, load_scenario
from sma_fmu.json_output import json_text
from sma_fmu.output_folder import staged_folder

__all__ = ["PATHS", "run_scenarios", "write_timeseries", "summary_table", "comparison_markdown"]

PATHS = {"fmu": run_fmus, "library": lambda scenario, fmu_dir: run_library(scenario)}


def write_timeseries(data, path):
    """CSV with a header of names and units (``t_s,R_ref_ohm,...``), time first."""
    header = ",".join(f"{name}_{unit}" if unit else name for name, unit in COLUMNS)
    table = np.column_stack([data[name].astype(float) for name, _ in COLUMNS])
    np.savetxt(path, table, delimiter=",", header=header, comments="", fmt="%.10g")


def summary_table(rows):
    """Plain-text table of runs (one dict per run with metrics and timing)."""
    lines = [f"{'scenario':<38}{'controller':<16}{'mode':<12}{'RMSE':>8}{'max|e|':>8}"
             f"{'IAE':>8}{'wall s':>8}{'x real':>8}",
             f"{'':<66}{'[ohm]':>8}{'[ohm]':>8}{'[ohm.s]':>8}"]
    for row in rows:
        m = row["metrics"]["overall"]
        lines.append(f"{row['scenario']:<38}{row['metrics']['controller']:<16}"
                     f"{row['metrics']['hysteresis_mode']:<12}{m['rmse_ohm']:>8.3f}"
                     f"{m['max_abs_ohm']:>8.3f}{m['iae_ohm_s']:>8.2f}{row['wall_time_s']:>8.2f}"
                     f"{row['real_time_factor']:>8.0f}")
    return "\n".join(lines)


def _groups(rows):
    groups = {}
    for row in rows:
        groups.setdefault(row["group"], []).append(row)
    return groups


def comparison_markdown(rows):
    """Markdown ranking the controllers by RMSE within each scenario group."""
    lines = ["# Controller comparison", "",
             f"Error e = R - R_ref over t >= {METRIC_START_S:g} s. Ranked by RMSE, best first.", ""]
    for group, members in _groups(rows).items():
        ranked = sorted(members, key=lambda r: r["metrics"]["overall"]["rmse_ohm"])
        mode = members[0]["metrics"]["hysteresis_mode"]
        lines += [f"## {group} ({mode} hysteresis)", "",
                  "| rank | controller | RMSE [ohm] | max abs e [ohm] | IAE [ohm s] | RMSE per load segment [ohm] |",
                  "|---:|---|---:|---:|---:|---|"]
        for rank, row in enumerate(ranked, start=1):
            m = row["metrics"]
            segments = ", ".join(f"{s['load_kg']:g} kg: {s['rmse_ohm']:.3f}"
                                 for s in m["segments"] if s["samples"])
            lines.append(f"| {rank} | {m['controller']} | {m['overall']['rmse_ohm']:.3f} | "
                         f"{m['overall']['max_abs_ohm']:.3f} | {m['overall']['iae_ohm_s']:.2f} | "
                         f"{segments} |")
        rmse = {r["metrics"]["controller"]: r["metrics"]["overall"]["rmse_ohm"] for r in members}
        if set(rmse) == set(CONTROLLERS):
            holds = rmse["pi"] > rmse["pi+ff-fixed"] > rmse["pi+ff-adaptive"]
            lines += ["", f"Paper's ordering RMSE(pi) > RMSE(pi+ff-fixed) > RMSE(pi+ff-adaptive): "
                          f"**{'holds' if holds else 'does not hold'}**; fixed - adaptive = "
                          f"{rmse['pi+ff-fixed'] - rmse['pi+ff-adaptive']:.3f} ohm."]
        lines.append("")
    return "\n".join(lines)


def run_scenarios(paths, out_dir, path="fmu", fmu_dir=DEFAULT_FMU_DIR, progress=print):
    """Run scenario files through ``path`` ("fmu" or "library"); write results; return rows.

    All files are read and checked before the first run, so a bad file costs no time.
    """
    if path not in PATHS:
        raise ValueError(f"path must be one of {', '.join(PATHS)}, got {path!r}")
    scenarios = [load_scenario(p) for p in paths]
    rows, series = [], {}
    with staged_folder(out_dir) as stage:
        for index, scenario in enumerate(scenarios, start=1):
            if len(scenarios) > 1:
                progress(f"[{index}/{len(scenarios)}] {scenario.name} ({path}) ...")
            result = PATHS[path](scenario, fmu_dir)
            folder = stage / scenario.name
            folder.mkdir()
            write_timeseries(result.data, folder / "timeseries.csv")
            metrics = scenario_metrics(result.data, scenario)
            metrics.update(path=path, wall_time_s=result.wall_time_s)
            (folder / "metrics.json").write_text(json_text(metrics), encoding="utf-8")
            plot_run(result.data, scenario, folder / "figure.png")
            rows.append({"scenario": scenario.name, "group": scenario.group, "metrics": metrics,
                         "wall_time_s": result.wall_time_s,
                         "real_time_factor": scenario.stop_time_s / result.wall_time_s})
            series[scenario.name] = (scenario, result.data)
        for group, members in _groups(rows).items():
            if len(members) > 1:
                runs = {series[r["scenario"]][0].controller.kind: series[r["scenario"]][1]
                        for r in members}
                plot_comparison(runs, f"{group}: controllers compared",
                                stage / f"comparison-{group}.png")
        (stage / "comparison.md").write_text(comparison_markdown(rows), encoding="utf-8")
        (stage / "summary.json").write_text(json_text(rows), encoding="utf-8")
    return rows


def timed_run(paths, out_dir, path, fmu_dir, progress=print):
    """:func:`run_scenarios`, then print the summary table; returns the rows."""
    start = time.perf_counter()
    rows = run_scenarios(paths, out_dir, path, fmu_dir, progress)
    progress(summary_table(rows))
    progress(f"results in {out_dir}/ ({time.perf_counter() - start:.1f} s)")
    return rows
