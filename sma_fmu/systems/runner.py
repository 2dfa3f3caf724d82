"""Run scenarios and write their results: CSV, metrics JSON, figures, comparison table.

For each scenario ``NAME`` in ``out_dir``: ``NAME/timeseries.csv`` (or ``.parquet``) and
``NAME/metrics.json``, written while the run goes, and with ``figures=True`` ``NAME/figure.png``. Scenarios with the same file name from different folders get
``FOLDER-NAME`` instead, so none overwrites another. For each group of scenarios (see
:attr:`~sma_fmu.cosim.scenario.Scenario.group`), with figures: ``comparison-GROUP.png``. Over the whole
run: ``comparison.md``, which ranks the runs by RMSE in each group, and ``summary.json``.
Each run's warnings (the model's, :mod:`sma_fmu.cosim.run_warnings`, then the metrics'
reachability warning) go into its ``metrics.json`` ``warnings`` and are printed once each,
``warning: NAME: TEXT``.
Everything is written into a temporary folder and moved into ``out_dir`` at the end.
Figures are drawn only when asked (``figures=True``, ``--figures``): without them no PNG is
written and matplotlib is never imported, so a run costs what its loop costs (docs/scenarios.md).

The C master (``master="c"``) is one :class:`~sma_fmu.systems.c_master.CMaster` for all the
scenarios: one host process, each FMU unpacked and loaded once; what that start-up cost is
each row's ``startup_s`` (the run's own ``wall_time_s`` leaves it out), and the run table
says so.
"""
import contextlib
import time
from collections import Counter

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.recording import (RunRecorder, TimeseriesWriter, interval_steps, progress_bar,
                                     timeseries_name)
from sma_fmu.cosim.report import comparison_markdown, groups, summary_table
from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.fmi.packaging.fmu_names import DEFAULT_FMU_DIR
from sma_fmu.files.json_output import json_text
from sma_fmu.files.output_folder import staged_folder

__all__ = ["PATHS", "FMU_MASTERS", "run_scenarios", "timed_run", "write_timeseries", "result_names",
           "comparison_labels"]


def _fmpy(scenario, fmu_dir, sink, events=False):
    from sma_fmu.cosim.master import run_fmus
    return run_fmus(scenario, fmu_dir, sink, events=events)


def _host(kind):
    def run(scenario, fmu_dir, sink):
        from sma_fmu.systems import runs   # libcosim, the SSP and container writers
        return getattr(runs, f"run_{kind}")(scenario, fmu_dir)
    return run


def _c_master(scenario, fmu_dir, sink):
    from sma_fmu.systems.c_master import run_c_master
    return run_c_master(scenario, fmu_dir, sink)


# path -> run(scenario, fmu_dir, sink): the loops stream their rows into the sink; the
# system hosts (libcosim) give a whole series, which the runner then feeds it (each path's
# modules are imported when it runs: a command pays only for its own)
PATHS = {"fmu": _fmpy,
         "library": lambda scenario, fmu_dir, sink: run_library(scenario, sink=sink),
         "ssp": _host("ssp"), "container": _host("container")}
# the masters of the "fmu" path (``--master``): fmpy (Python) or the C master (loop_host.c;
# run_scenarios keeps one for all its scenarios)
FMU_MASTERS = {"fmpy": PATHS["fmu"], "c": _c_master}


def write_timeseries(data, path, fmt="csv"):
    """A whole series as a file (``fmt``: CSV, a header of names and units ``t_s,R_ref_ohm,...``
    with time first; or Parquet)."""
    writer = TimeseriesWriter(path, fmt)
    writer.write(data)
    writer.close()


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


def run_scenarios(paths, out_dir, path="fmu", fmu_dir=DEFAULT_FMU_DIR, progress=print,
                  output_interval_s=None, fmt="csv", master="fmpy", events=False,
                  timeout_s=None, figures=False):
    """Run scenario files through ``path`` (a key of :data:`PATHS`); write results; return rows.

    All files are read and checked before the first run, so a bad file costs no time, and
    a failed run leaves ``out_dir`` as it was. ``output_interval_s`` [s]: record every
    k-th step in the time series and figures (None: the scenario's ``[scenario]
    output_interval_s``, else every step); the metrics count every step. ``fmt``: the time
    series' format, "csv" or "parquet". ``master``: the FMU path's master, a key of
    :data:`FMU_MASTERS` (``"c"`` only with ``path="fmu"``). ``events``: the fmpy master
    runs FMI 3.0 FMUs with event mode and early return (:mod:`sma_fmu.cosim.event_drive`;
    only with ``path="fmu"``, ``master="fmpy"``). ``timeout_s`` [s] (``--master c``
    only): the longest the C master may send nothing before the run fails (None:
    :data:`~sma_fmu.systems.c_master.DEFAULT_TIMEOUT_S`). Each run streams into its files
    (:class:`~sma_fmu.cosim.recording.RunRecorder`): memory does not grow with its length.
    ``figures``: also write the figures (the command line's ``--figures``; without
    them matplotlib is never imported). On ``path="container"`` a scenario whose plant warns
    at its start is refused before any run (:func:`~sma_fmu.systems.container.container_refusal`).
    """
    if path not in PATHS:
        raise ValueError(f"path must be one of {', '.join(PATHS)}, got {path!r}")
    if master not in FMU_MASTERS:
        raise ValueError(f"--master must be one of {', '.join(FMU_MASTERS)}, got {master!r}")
    if master != "fmpy" and path != "fmu":
        raise ValueError(f"--master {master} runs the FMUs (--path fmu), not --path {path}")
    if events and (path != "fmu" or master != "fmpy"):
        raise ValueError(f"--events runs the FMUs through the fmpy master (--path fmu --master "
                         f"fmpy), not --path {path} --master {master}")
    if timeout_s is not None and master != "c":
        raise ValueError(f"--timeout applies to the C master (--master c), not --master {master}")
    if timeout_s is not None and not timeout_s > 0:
        raise ValueError(f"--timeout must be a number of seconds > 0, got {timeout_s!r}")
    run = FMU_MASTERS[master] if path == "fmu" else PATHS[path]
    if events:
        run = lambda scenario, fmu_dir, sink: _fmpy(scenario, fmu_dir, sink, events=True)  # noqa: E731
    timeseries_name(fmt)
    scenarios = [load_scenario(p) for p in paths]
    if path == "container":
        from sma_fmu.systems.container import container_refusal
        for scenario in scenarios:
            refusal = container_refusal(scenario)
            if refusal:
                raise ValueError(f"{scenario.path}: {refusal}")
    every = [interval_steps(output_interval_s, s.step_s, "--output-interval")
             if output_interval_s is not None
             else interval_steps(s.output_interval_s, s.step_s, f"{s.path}: [scenario] output_interval_s")
             for s in scenarios]
    names = result_names(scenarios)
    labels = comparison_labels(scenarios, names)
    rows, series = [], {}
    with staged_folder(out_dir) as stage, contextlib.ExitStack() as stack:
        c_master = None
        if path == "fmu" and master == "c":   # one C master for every scenario
            from sma_fmu.systems.c_master import DEFAULT_TIMEOUT_S, CMaster
            c_master = stack.enter_context(CMaster(fmu_dir, timeout_s=timeout_s or DEFAULT_TIMEOUT_S))
            run = lambda scenario, fmu_dir, sink: c_master.run(scenario, sink)  # noqa: E731
        if figures:
            from sma_fmu.cosim.plots import plot_comparison, plot_run
        for index, (scenario, name, label) in enumerate(zip(scenarios, names, labels), start=1):
            if len(scenarios) > 1:
                progress(f"[{index}/{len(scenarios)}] {name} ({path}) ...")
            folder = stage / name
            folder.mkdir()
            startup_s = c_master.startup_s if c_master else 0.0
            metrics, figure_rows, wall_time_s = _record_run(scenario, run, fmu_dir, folder,
                                                             every[index - 1], fmt)
            metrics.update(path=path, wall_time_s=wall_time_s)
            if path == "fmu":
                metrics["master"] = master
            if events:
                metrics["events"] = True
            for warning in metrics["warnings"]:
                progress(f"warning: {scenario.name}: {warning}")
            (folder / "metrics.json").write_text(json_text(metrics), encoding="utf-8")
            if figures:
                plot_run(figure_rows, scenario, folder / "figure.png")
            rows.append({"scenario": name, "label": label, "group": scenario.group,
                         "metrics": metrics, "wall_time_s": wall_time_s,
                         "real_time_factor": scenario.stop_time_s / wall_time_s})
            if c_master is not None:   # the host started, FMUs unpacked and loaded for it
                rows[-1]["startup_s"] = c_master.startup_s - startup_s
            series[name] = (scenario, figure_rows)
        for group, members in groups(rows).items():
            if len(members) > 1 and figures:
                runs = {row["label"]: series[row["scenario"]][1] for row in members}
                plot_comparison(runs, series[members[0]["scenario"]][0],
                                f"{group}: controllers compared", stage / f"comparison-{group}.png")
        (stage / "comparison.md").write_text(comparison_markdown(rows), encoding="utf-8")
        (stage / "summary.json").write_text(json_text(rows), encoding="utf-8")
    return rows


def _record_run(scenario, run, fmu_dir, folder, every, fmt):
    """Run one scenario with ``run`` (a value of :data:`PATHS`) into ``folder`` through a
    :class:`RunRecorder`; returns (metrics, figure rows, wall time [s] of the run itself)."""
    bar = progress_bar(scenario.steps + 1, scenario.name)
    recorder = RunRecorder(scenario, folder, every, fmt, None if bar is None else bar.update)
    try:
        result = run(scenario, fmu_dir, recorder)
        wall_time_s = result.wall_time_s - recorder.seconds  # the run, not its recording
        if result.data is not None:  # a host that kept the whole series
            recorder.feed(result.data)
    finally:
        metrics, figure_rows = recorder.close()
        if bar is not None:
            bar.close()
    # the model's warnings (the steppers', or the FMUs' log), then the metrics' own
    metrics["warnings"] = result.warnings + metrics["warnings"]
    return metrics, figure_rows, wall_time_s


def timed_run(paths, out_dir, path, fmu_dir, progress=print, output_interval_s=None, fmt="csv",
              master="fmpy", events=False, timeout_s=None, figures=False):
    """:func:`run_scenarios`, then print the summary table; returns the rows."""
    start = time.perf_counter()
    rows = run_scenarios(paths, out_dir, path, fmu_dir, progress, output_interval_s, fmt, master,
                         events, timeout_s, figures)
    progress(summary_table(rows))
    progress(f"results in {out_dir}/ ({time.perf_counter() - start:.1f} s)"
             + ("" if figures else "; no figures: --figures draws them"))
    return rows
