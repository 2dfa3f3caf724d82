"""Run scenarios and write their results: CSV, metrics JSON, figures, comparison table.

For each scenario ``NAME`` in ``out_dir``: ``NAME/timeseries.csv``, ``NAME/metrics.json``
and ``NAME/figure.png``. Scenarios with the same file name from different folders get
``FOLDER-NAME`` instead, so none overwrites another. For each group of scenarios (see
:attr:`~sma_fmu.cosim.scenario.Scenario.group`): ``comparison-GROUP.png``. Over the whole
run: ``comparison.md``, which ranks the runs by RMSE in each group, and ``summary.json``.
Everything is written into a temporary folder and moved into ``out_dir`` at the end.
"""
import time
from collections import Counter

import numpy as np

from sma_fmu.cosim.loop import COLUMN_NAMES, COLUMNS, run_library
from sma_fmu.cosim.master import run_fmus
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.plots import plot_comparison, plot_run
from sma_fmu.cosim.report import comparison_markdown, groups, summary_table
from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.fmi.build import DEFAULT_FMU_DIR
from sma_fmu.files.json_output import json_text
from sma_fmu.files.output_folder import staged_folder
from sma_fmu.systems.runs import run_container, run_ssp

__all__ = ["PATHS", "run_scenarios", "timed_run", "write_timeseries", "result_names",
           "comparison_labels"]

PATHS = {"fmu": run_fmus, "library": lambda scenario, fmu_dir: run_library(scenario),
         "ssp": run_ssp, "container": run_container}


def write_timeseries(data, path):
    """CSV with a header of names and units (``t_s,R_ref_ohm,...``), time first."""
    header = ",".join(COLUMN_NAMES)
    table = np.column_stack([data[name].astype(float) for name, _ in COLUMNS])
    np.savetxt(path, table, delimiter=",", header=header, comments="", fmt="%.10g")


def result_names(scenarios):
    """A distinct result-folder name per scenario: its name, or FOLDER-NAME where names clash."""
    counts = Counter(s.name for s in scenarios)
    names = [s.name if counts[s.name] == 1 else f"{s.path.parent.name}-{s.name}" for s in scenarios]
    seen = Counter()
    unique = []
    for name in names:
        seen[name] += 1
        unique.append(name if seen[name] == 1 else f"{name}-{seen[name]}")
    return unique


def comparison_labels(scenarios, names):
    """Label of each run in its group's comparison: the controller kind where it is the only
    run of that kind in the group, otherwise its result name (the scenario's)."""
    kinds = Counter((s.group, s.controller.kind) for s in scenarios)
    return [s.controller.kind if kinds[s.group, s.controller.kind] == 1 else name
            for s, name in zip(scenarios, names)]


def run_scenarios(paths, out_dir, path="fmu", fmu_dir=DEFAULT_FMU_DIR, progress=print):
    """Run scenario files through ``path`` (a key of :data:`PATHS`); write results; return rows.

    All files are read and checked before the first run, so a bad file costs no time, and
    a failed run leaves ``out_dir`` as it was.
    """
    if path not in PATHS:
        raise ValueError(f"path must be one of {', '.join(PATHS)}, got {path!r}")
    scenarios = [load_scenario(p) for p in paths]
    names = result_names(scenarios)
    labels = comparison_labels(scenarios, names)
    rows, series = [], {}
    with staged_folder(out_dir) as stage:
        for index, (scenario, name, label) in enumerate(zip(scenarios, names, labels), start=1):
            if len(scenarios) > 1:
                progress(f"[{index}/{len(scenarios)}] {name} ({path}) ...")
            result = PATHS[path](scenario, fmu_dir)
            folder = stage / name
            folder.mkdir()
            write_timeseries(result.data, folder / "timeseries.csv")
            metrics = scenario_metrics(result.data, scenario)
            metrics.update(path=path, wall_time_s=result.wall_time_s)
            for warning in metrics["warnings"]:
                progress(f"warning: {scenario.name}: {warning}")
            (folder / "metrics.json").write_text(json_text(metrics), encoding="utf-8")
            plot_run(result.data, scenario, folder / "figure.png")
            rows.append({"scenario": name, "label": label, "group": scenario.group,
                         "metrics": metrics, "wall_time_s": result.wall_time_s,
                         "real_time_factor": scenario.stop_time_s / result.wall_time_s})
            series[name] = (scenario, result.data)
        for group, members in groups(rows).items():
            if len(members) > 1:
                runs = {row["label"]: series[row["scenario"]][1] for row in members}
                plot_comparison(runs, series[members[0]["scenario"]][0],
                                f"{group}: controllers compared", stage / f"comparison-{group}.png")
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
