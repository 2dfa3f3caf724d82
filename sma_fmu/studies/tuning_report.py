"""``sma-fmu tune``'s reports: the console lines, the ``[controller]`` snippet, report.md.

A stroke scenario's record names its criterion and is reported in the unit of it (um, with
R's numbers in ohm beside; :mod:`sma_fmu.studies.criterion`); a resistance scenario's as
ever, in ohm.
"""
import json
from datetime import datetime, timezone

from sma_fmu.cosim.scenario import CONTROLLERS
from sma_fmu.fmi.loop.gains import GAIN_KEYS
from sma_fmu.studies.criterion import UNITS, stroke_markdown

__all__ = ["SHAPED_KEYS", "controller_snippet", "ranking_markdown", "print_record"]

SHAPED_KEYS = ("shaping", "power_cap_W", "anticipation_s")   # kept in the snippet as given


def controller_snippet(record):
    """The tuned gains as a ``[controller]`` TOML table that pastes into the scenario."""
    lines = [f"# sma-fmu tune {record['scenario']} ({datetime.now(timezone.utc).date()}): "
             f"RMSE {record['rmse_ohm']['tuned']:.4f} ohm, against "
             f"{record['rmse_ohm']['given']:.4f} ohm at the scenario's gains"]
    unit = UNITS[record.get("criterion", "resistance")]
    if "criterion" in record:
        lines[0] = (f"# sma-fmu tune {record['scenario']} ({datetime.now(timezone.utc).date()}), "
                    f"criterion {record['criterion']}: stroke RMSE "
                    f"{record['rmse_um']['tuned']:.1f} um, against "
                    f"{record['rmse_um']['given']:.1f} um at the scenario's gains "
                    f"(R: {record['rmse_ohm']['tuned']:.4f} ohm, against "
                    f"{record['rmse_ohm']['given']:.4f})")
    robust = record.get("robust")
    if robust:
        lines.append(f"# robust: quantile {robust['quantile']:g} of {robust['draws']} draws "
                     f"(noise, +-{100 * robust['spread']:g} % wire): "
                     f"{robust[f'score_tuned_{unit}']:.4f} {unit}, against "
                     f"{robust[f'score_given_{unit}']:.4f}")
    if "joint" in record:
        lines.append(f"# tuned jointly with {', '.join(record['joint']['scenarios'])}: score "
                     f"{record['joint']['ratio']:.3f} x the given gains' here, worst "
                     f"{record['joint']['worst_ratio']:.3f}")
    margins = record["margins"]["tuned"]
    lines += [f"# margins of the linearised loop: gain {margins['gain_margin_dB']:.1f} dB, "
              f"phase {margins['phase_margin_deg']:.1f} deg",
              "[controller]", f"kind = {json.dumps(record['controller'])}"]
    if record.get("inverse", "major") != "major":
        lines.append(f"inverse = {json.dumps(record['inverse'])}")
    lines += [f"{key} = {json.dumps(record[key])}" for key in SHAPED_KEYS
              if record.get(key) not in (None, "none", 0.0)]
    lines += [f"{GAIN_KEYS[name]} = {value!r}" for name, value in record["tuned"].items()]
    return "\n".join(lines) + "\n"


def _label(record):
    """The controller's column: its kind, with a non-default inverse in parentheses."""
    inverse = record.get("inverse", "major")
    return record["controller"] + ("" if inverse == "major" else f" ({inverse})")


def ranking_markdown(records):
    """Per group of scenarios with every controller: RMSE [ohm] and order, given vs tuned gains.

    Columns: the three controllers, then any other inverse present (a group without it
    shows "-" there and ranks the rest). Stroke scenarios' records are in a table of their
    own (:func:`~sma_fmu.studies.criterion.stroke_markdown`), after the others'.
    """
    groups, labels = {}, list(CONTROLLERS)
    for record in records:
        label = _label(record)
        if label not in labels:
            labels.append(label)
        groups.setdefault((record["group"], record["hysteresis_mode"]), {})[label] = record
    windows = ", ".join(sorted({record["window"] for record in records}))
    lines = ["# Tuned gains", "", f"RMSE of R - R_ref over {windows} [ohm], on the library path.",
             "", "| scenario | mode | gains | " + " | ".join(labels) + " | ranking, best first |",
             "|---|---|---|" + "---:|" * len(labels) + "---|"]
    for (group, mode), members in groups.items():
        if not set(CONTROLLERS) <= set(members):
            continue
        for gains in ("given", "tuned"):
            rmse = {c: members[c]["rmse_ohm"][gains] for c in labels if c in members}
            order = " < ".join(sorted(rmse, key=rmse.get))
            lines.append(f"| {group} | {mode} | {gains} | " +
                         " | ".join(f"{rmse[c]:.3f}" if c in rmse else "-" for c in labels)
                         + f" | {order} |")
    robust = next((r["robust"] for r in records if r.get("robust")), None)
    plain = [record for record in records if "criterion" not in record]
    score = "" if robust is None else (f" | score given | score tuned")
    if plain:
        lines += ["", f"| scenario | RMSE given | RMSE tuned{score} | tuned values "
                  "(* at a bound) | gain margin [dB] | phase margin [deg] |",
                  "|---|---:|---:|" + ("---:|---:|" if robust else "") + "---|---:|---:|"]
    else:                                        # stroke scenarios only: their table alone
        lines = lines[:1]
    for record in plain:
        values = ", ".join(f"{name} = {value:.4g}{'*' if name in record['at_bound'] else ''}"
                           for name, value in record["tuned"].items())
        scores = "" if robust is None else (
            f" | {record['robust']['score_given_ohm']:.3f} | "
            f"{record['robust']['score_tuned_ohm']:.3f}"
            if record.get("robust") else " | - | -")
        margins = record["margins"]["tuned"]
        lines.append(f"| {record['scenario']} | {record['rmse_ohm']['given']:.3f} | "
                     f"{record['rmse_ohm']['tuned']:.3f}{scores} | {values} | "
                     f"{margins['gain_margin_dB']:.1f} | {margins['phase_margin_deg']:.1f} |")
    lines += stroke_markdown(records)
    if any("joint" in record for record in records):
        lines += ["", "Tuned jointly: one gain set for all the scenarios, minimising the worst "
                      "of their scores relative to their given gains' (" + ", ".join(
                          f"{r['scenario']} {r['joint']['ratio']:.3f}" for r in records) + ")."]
    if robust is not None:
        lines += ["", f"Score: the {robust['quantile']:g} quantile of the RMSE over "
                      f"{robust['draws']} draws (noise stream; {', '.join(robust['parameters'])} "
                      f"each x U[{1 - robust['spread']:g}, {1 + robust['spread']:g}]). Margins: "
                      "the loop linearised where the wire is steepest."]
    return "\n".join(lines) + "\n"


def print_record(record, robust, progress):
    """The console's lines of one tuned record: the criterion's RMSE, given -> tuned."""
    gains = ", ".join(f"{k} = {v:.4g}" for k, v in record["tuned"].items())
    unit = UNITS[record.get("criterion", "resistance")]
    if "criterion" in record:
        progress(f"    criterion {record['criterion']}: stroke RMSE "
                 f"{record['rmse_um']['given']:.1f} -> {record['rmse_um']['tuned']:.1f} um, "
                 f"RMSE {record['rmse_ohm']['given']:.4f} -> "
                 f"{record['rmse_ohm']['tuned']:.4f} ohm: {gains}")
    else:
        progress(f"    RMSE {record['rmse_ohm']['given']:.4f} -> "
                 f"{record['rmse_ohm']['tuned']:.4f} ohm: {gains}")
    if robust is not None:
        progress(f"    robust score {record['robust'][f'score_given_{unit}']:.4f} -> "
                 f"{record['robust'][f'score_tuned_{unit}']:.4f} {unit}")
    if "joint" in record:
        progress(f"    jointly tuned: score {record['joint']['ratio']:.3f} x the given gains' "
                 f"(worst of all {record['joint']['worst_ratio']:.3f})")
