"""Text reports of a set of runs: the summary table and the Markdown ranking per group.

A row is the dict :func:`sma_fmu.systems.runner.run_scenarios` returns per run: ``scenario``
(its result folder name), ``label`` (its name in the comparisons), ``group``, ``metrics``,
``wall_time_s``, ``real_time_factor``. A metric that could not be computed (no sample in
its window) is None and shows as "n/a".
"""
from sma_fmu.cosim.scenario import CONTROLLERS

__all__ = ["summary_table", "comparison_markdown", "groups"]


def _number(value, spec):
    return "n/a" if value is None else format(value, spec)


def groups(rows):
    """{group: [rows]} in the order the groups first appear."""
    grouped = {}
    for row in rows:
        grouped.setdefault(row["group"], []).append(row)
    return grouped


def summary_table(rows):
    """Plain-text table of runs (one dict per run with metrics and timing)."""
    lines = [f"{'scenario':<48}{'controller':<16}{'mode':<12}{'RMSE':>8}{'max|e|':>8}"
             f"{'IAE':>8}{'wall s':>8}{'x real':>8}",
             f"{'':<76}{'[ohm]':>8}{'[ohm]':>8}{'[ohm.s]':>8}"]
    strokes = [row for row in rows if "stroke" in row["metrics"]]
    if strokes:
        lines[0] += f"{'stroke':>10}{'max|e|':>10}"
        lines[1] += f"{'':<16}{'RMSE [um]':>10}{'[um]':>10}"
    for row in rows:
        m = row["metrics"]["overall"]
        stroke = row["metrics"].get("stroke")
        lines.append(f"{row['scenario']:<48}{row['metrics']['controller']:<16}"
                     f"{row['metrics']['hysteresis_mode']:<12}{_number(m['rmse_ohm'], '>8.3f'):>8}"
                     f"{_number(m['max_abs_ohm'], '>8.3f'):>8}{_number(m['iae_ohm_s'], '>8.2f'):>8}"
                     f"{row['wall_time_s']:>8.2f}{row['real_time_factor']:>8.0f}"
                     + ("" if stroke is None else f"{_number(stroke['rmse_um'], '>10.1f'):>10}"
                        f"{_number(stroke['max_abs_um'], '>10.1f'):>10}"))
    lines.append("wall s: each run's own time, from its start to its last row, less the time "
                 "spent writing its files")
    if strokes:
        lines.append("stroke: the stroke x_0 - x against a stroke reference, over the metrics "
                     "window")
    startup = [row["startup_s"] for row in rows if "startup_s" in row]
    if startup:
        lines.append(f"the C master's start-up (host started, FMUs read, unpacked and loaded), "
                     f"paid once for all the runs and in no run's wall s: {sum(startup):.2f} s")
    return "\n".join(lines)


def _rank_key(row):
    rmse = row["metrics"]["overall"]["rmse_ohm"]
    return (rmse is None, rmse or 0.0)


def _paper_ordering(members):
    """The sentence on the paper's ordering, when the group has its three controllers once each."""
    rmse = {r["label"]: r["metrics"]["overall"]["rmse_ohm"] for r in members}
    if not set(CONTROLLERS) <= set(rmse) or any(rmse[c] is None for c in CONTROLLERS):
        return []
    holds = rmse["pi"] > rmse["pi+ff-fixed"] > rmse["pi+ff-adaptive"]
    return ["", f"Paper's ordering RMSE(pi) > RMSE(pi+ff-fixed) > RMSE(pi+ff-adaptive): "
                f"**{'holds' if holds else 'does not hold'}**; fixed - adaptive = "
                f"{rmse['pi+ff-fixed'] - rmse['pi+ff-adaptive']:.3f} ohm."]


def comparison_markdown(rows):
    """Markdown ranking the runs by RMSE within each scenario group."""
    lines = ["# Controller comparison", "",
             "Error e = R - R_ref over each run's metrics window. Ranked by RMSE, best first.", ""]
    for group, members in groups(rows).items():
        first = members[0]["metrics"]
        lines += [f"## {group} ({first['hysteresis_mode']} hysteresis, {first['window']})", "",
                  "| rank | run | controller | RMSE [ohm] | max abs e [ohm] | IAE [ohm s] | "
                  "RMSE per load segment [ohm] |",
                  "|---:|---|---|---:|---:|---:|---|"]
        for rank, row in enumerate(sorted(members, key=_rank_key), start=1):
            m = row["metrics"]
            segments = ", ".join(f"{s['load_kg']:g} kg: {_number(s['rmse_ohm'], '.3f')}"
                                 for s in m["segments"] if s["samples"])
            overall = m["overall"]
            lines.append(f"| {rank} | {row['label']} | {m['controller']} | "
                         f"{_number(overall['rmse_ohm'], '.3f')} | "
                         f"{_number(overall['max_abs_ohm'], '.3f')} | "
                         f"{_number(overall['iae_ohm_s'], '.2f')} | {segments} |")
        lines += _paper_ordering(members)
        lines.append("")
    return "\n".join(lines)
