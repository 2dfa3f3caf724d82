"""The results of a sweep: one table (Parquet and CSV), a summary (JSON, Markdown), figures.

Read from the part files the runs wrote (``OUT/runs``); one row per run of the spec, in
run order, with its inputs (the overrides, the axis point and draw numbers), status,
error and metrics. The summary counts the statuses and, per base scenario, gives the RMSE
statistics and the best run. Figures (matplotlib Figure objects, no pyplot): a heat map of
the mean RMSE over the first two axes of a grid, RMSE against a single axis, and for a
Monte Carlo the distribution of the RMSE with the wire parameter it correlates most with.
"""
from pathlib import Path

import numpy as np
import pandas as pd

from sma_fmu.files.json_output import json_text
from sma_fmu.files.output_folder import staged_folder
from sma_fmu.files.png_output import png_bytes
from sma_fmu.studies.figures import distribution_figure, heat_map_figure, line_figure

__all__ = ["PARTS", "read_parts", "summary", "summary_markdown", "write_results"]

PARTS = "runs"   # the folder of OUT that holds the part files


def read_parts(out, columns=None):
    """All rows written to ``out``/runs, one per run (a final status beats "error").

    ``columns``: read only these (with "run_id" and "status"); default: all.
    """
    parts = sorted((Path(out) / PARTS).glob("part-*.parquet"))
    if not parts:
        return pd.DataFrame(columns=columns or ["run_id", "scenario", "status", "error"])
    table = pd.concat([pd.read_parquet(p, columns=columns) for p in parts], ignore_index=True)
    table["_retry"] = table["status"] == "error"
    table = table.sort_values(["run_id", "_retry"], kind="stable")
    return table.drop_duplicates("run_id").drop(columns="_retry").reset_index(drop=True)


def _statistics(values):
    if values.size == 0:
        return None
    return {"runs": int(values.size), "mean": float(values.mean()),
            "std": float(values.std(ddof=1)) if values.size > 1 else 0.0,
            "min": float(values.min()), "p05": float(np.percentile(values, 5)),
            "median": float(np.median(values)), "p95": float(np.percentile(values, 95)),
            "max": float(values.max())}


def summary(spec, table):
    """Counts, and per base scenario the RMSE statistics [ohm] and the best run's inputs."""
    counts = {status: int((table["status"] == status).sum()) for status in ("ok", "failed", "error")}
    scenarios = {}
    for name, rows in table.groupby("scenario", sort=False):
        ok = rows[rows["status"] == "ok"]
        entry = {"runs": int(len(rows)), "ok": int(len(ok)),
                 "rmse_ohm": _statistics(ok["rmse_ohm"].to_numpy(dtype=float)) if len(ok) else None}
        if len(ok):
            best = ok.loc[ok["rmse_ohm"].idxmin()]
            entry["best"] = {"run_id": int(best["run_id"]), "rmse_ohm": float(best["rmse_ohm"]),
                             **{key: _plain(best[key]) for key in spec.inputs if key in best}}
        failures = rows[rows["status"] != "ok"]["error"].value_counts().head(5)
        entry["failure_reasons"] = {str(k): int(v) for k, v in failures.items()}
        scenarios[name] = entry
    return {"spec": str(spec.path), "description": spec.description, "runs": int(len(table)),
            "status": counts, "axes": {"kind": spec.axes_kind, "keys": list(spec.axes)},
            "monte_carlo": None if spec.report is None else
            {"report": str(spec.report), "samples": len(spec.draws)},
            "seed": spec.seed, "scenarios": scenarios}


def _plain(value):
    if isinstance(value, (np.floating, float)):
        return float(value)
    if isinstance(value, (np.integer, int)):
        return int(value)
    return value if isinstance(value, str) else str(value)


def summary_markdown(document):
    """The summary as a short Markdown report."""
    status = document["status"]
    lines = [f"# Sweep: {document['spec']}", "", document["description"], "",
             f"{document['runs']} runs: {status['ok']} ok, {status['failed']} failed, "
             f"{status['error']} task errors.", "",
             "| scenario | ok | RMSE mean [ohm] | std | p05 | median | p95 | best RMSE | best inputs |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---|"]
    for name, entry in document["scenarios"].items():
        stats = entry["rmse_ohm"]
        if stats is None:
            lines.append(f"| {name} | 0 | | | | | | | |")
            continue
        best = entry["best"]
        inputs = ", ".join(f"{k} = {v:.4g}" if isinstance(v, float) else f"{k} = {v}"
                           for k, v in best.items() if k not in ("run_id", "rmse_ohm"))
        lines.append(f"| {name} | {entry['ok']} | {stats['mean']:.4f} | {stats['std']:.4f} | "
                     f"{stats['p05']:.4f} | {stats['median']:.4f} | {stats['p95']:.4f} | "
                     f"{best['rmse_ohm']:.4f} | {inputs} |")
    failures = {reason: count for entry in document["scenarios"].values()
                for reason, count in entry["failure_reasons"].items()}
    if failures:
        lines += ["", "Failures (most common reasons):", ""]
        lines += [f"- {count} x {reason}" for reason, count in failures.items()]
    return "\n".join(lines) + "\n"


def _figures(spec, table):
    """{file name: Figure} for the study's design."""
    figures = {}
    ok = table[table["status"] == "ok"]
    numeric = [key for key in spec.axes if key in ok and pd.api.types.is_numeric_dtype(ok[key])]
    for name, rows in ok.groupby("scenario", sort=False):
        if spec.axes_kind == "grid" and len(numeric) >= 2:
            figures[f"heatmap-{name}.png"] = heat_map_figure(rows, numeric[0], numeric[1], name)
        elif len(numeric) == 1:
            figures[f"rmse-{name}.png"] = line_figure(rows, numeric[0], name)
        if spec.draws:
            wire = [key for key in spec.draws[0] if key in rows]
            figures[f"distribution-{name}.png"] = distribution_figure(rows, wire, name)
    return figures


def write_results(spec, out):
    """Write results.parquet, results.csv, summary.json, summary.md and figures; return summary."""
    table = read_parts(out)
    document = summary(spec, table)
    figures = {name: png_bytes(figure, dpi=100) for name, figure in _figures(spec, table).items()}
    csv = table.to_csv(index=False, na_rep="")
    with staged_folder(out, report=False) as stage:   # beside the runs' parts
        table.to_parquet(stage / "results.parquet", index=False)
        (stage / "results.csv").write_text(csv, encoding="utf-8")
        (stage / "summary.json").write_text(json_text(document), encoding="utf-8")
        (stage / "summary.md").write_text(summary_markdown(document), encoding="utf-8")
        if figures:
            (stage / "figures").mkdir()
            for name, png in figures.items():
                (stage / "figures" / name).write_bytes(png)
    document["figures"] = sorted(figures)
    document["out"] = str(out)
    return document
