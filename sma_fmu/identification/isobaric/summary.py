"""The isobaric fit's half-strain table (data and model at every stress, and their slopes
against stress) and its text summary."""
from pathlib import Path

import numpy as np

from sma_fmu.identification.coverage import DONE_SHARE, share_done
from sma_fmu.identification.isobaric.halfway import (half_strain_temperature, stress_slope,
                                                     transformation_strain)
from sma_fmu.identification.isobaric.residual_parts import parts_line
from sma_fmu.identification.isobaric.synthetic import stress_of_load
from sma_fmu.identification.isobaric.terms import branch_curve
from sma_fmu.runtime.constants import COOLING, HEATING

__all__ = ["half_strain_table", "format_isobaric_report", "unfinished_note", "GRID_POINTS"]

GRID_POINTS = 2000
_WORD = {HEATING: "heating", COOLING: "cooling"}


def _median(values):
    values = [v for v in values if np.isfinite(v)]
    return float(np.median(values)) if values else float("nan")


def half_strain_table(files, fit):
    """{"per_file": [{file, stress_MPa, data/model heating/cooling [degC], transformation
    strain data/model [1]}], "slopes_K_per_MPa": {data/model: {heating, cooling}}}.

    Data: the median over the file's complete branches of each direction, against the
    measured (smoothed) temperature; model: the model branch over the same temperature range
    (no lag: what a lab's own construction gives). Transformation strain: the span between
    the model's (the data's) sloped baselines at the half-strain temperature, the median over
    the file's complete branches of both directions."""
    rows = []
    for data, wire in zip(files, fit.profiles):
        entry = {"file": data.path.name,
                 "stress_MPa": stress_of_load(data.load, fit.params.diameter)}
        spans_data, spans_model = [], []
        for d in (HEATING, COOLING):
            found_data, found_model = [], []
            for b in data.branches:
                if not b.complete or b.direction != d:
                    continue
                t, e = data.smoothed[b.start:b.stop], data.strain[b.start:b.stop]
                found_data.append(half_strain_temperature(t, e, d))
                grid = np.linspace(float(t.min()), float(t.max()), GRID_POINTS)
                model, _, _ = branch_curve(grid, data.load, d, fit.params, data.reference_length)
                found_model.append(half_strain_temperature(grid, model, d))
                spans_data.append(transformation_strain(t, e, d))
                spans_model.append(transformation_strain(grid, model, d))
            entry[f"data_{_WORD[d]}_degC"] = _median(found_data)
            entry[f"model_{_WORD[d]}_degC"] = _median(found_model)
            ends = [b for b in data.branches if b.complete and b.direction == d]
            note = unfinished_note(data.smoothed, ends, data.load, d, fit.params)
            entry.setdefault("model_unfinished", []).extend([note] if note else [])
        entry["data_transformation_strain"] = _median(spans_data)
        entry["model_transformation_strain"] = _median(spans_model)
        rows.append(entry)
    slopes = {}
    for source in ("data", "model"):
        slopes[source] = {w: stress_slope([r["stress_MPa"] for r in rows],
                                          [r[f"{source}_{w}_degC"] for r in rows])[0]
                          for w in ("heating", "cooling")}
    return {"per_file": rows, "slopes_K_per_MPa": slopes,
            "note": "half-strain temperatures: half way between the sloped baselines of the "
                    "tangent construction, on the measured (smoothed) temperature; spans: the "
                    "transformation strain between the baselines at that temperature [1]"}


def unfinished_note(temperature, branches, load, direction, params):
    """A note ("" when none) when the model's transformation is less than DONE_SHARE done
    at the far end of the file's ``branches`` of ``direction`` (heating: the hottest sample
    of each, cooling: the coldest; the median over them): the rest of it lies beyond the
    data, the model's extrapolation, which the identified file's FMUs then run."""
    if not branches:
        return ""
    ends = [float((np.max if direction == HEATING else np.min)(temperature[b.start:b.stop]))
            for b in branches]
    end = float(np.median(ends))
    done = share_done(end, load, direction, params)
    if done >= DONE_SHARE:
        return ""
    return (f"{_WORD[direction]}: the data end at {end:.4g} degC with "
            f"{100.0 * (1.0 - done):.2g} % of the model's transformation still to come; that "
            f"part is the model's extrapolation beyond the data (measure further to pin it)")


def _table(rows, header):
    """Lines of a table whose columns are as wide as their widest cell (first left-aligned)."""
    widths = [max(len(str(r[i])) for r in [header] + rows) for i in range(len(header))]
    return ["  ".join(str(c).ljust(w) if i == 0 else str(c).rjust(w)
                      for i, (c, w) in enumerate(zip(r, widths))).rstrip()
            for r in [header] + rows]


def format_isobaric_report(report):
    """A short text summary of an isobaric fit report (each line once; how the cycles were
    found is printed while reading)."""
    rms = report["residual_rms"]
    solver = report["solver"]
    noise = report.get("noise_judged", report["noise_estimates"])
    state = "converged" if solver["converged"] else f"NOT CONVERGED ({solver['message']})"
    lines = [f"isobaric fit: {report['points']} points in {len(report['files'])} file(s); "
             f"{solver['seconds']:.2f} s ({solver['evaluations']} evaluations), {state}",
             f"residual RMS (noise): strain {rms['strain']:.3g} ({noise['strain']:.3g}), "
             f"temperature {rms['temperature_K']:.3g} K ({noise['temperature_K']:.3g} K)"
             + (f", resistance {rms['resistance_ohm']:.3g} ohm ({noise['resistance_ohm']:.3g} ohm)"
                if rms["resistance_ohm"] else ""),
             report["verdict"], *report.get("noise_floor_notes", [])]
    if report.get("noise_smooth_note"):
        lines.append(f"note: {report['noise_smooth_note']}")
    if "strain residual" in report["verdict"]:     # not explained: say where it sits
        lines += [parts_line(Path(entry["file"]).name, entry["strain_residual_parts"])
                  for entry in report["files"] if entry.get("strain_residual_parts")]
    law = report.get("centre_law") or {"option": "linear"}
    for note in (report.get("lag_choice", {}).get("note"), report.get("stage_note"),
                 *report.get("slopes_not_fitted", []),
                 law.get("note") if law["option"] != "linear" else None):
        if note:
            lines.append(note)
    if report.get("on_bound"):
        lines.append("on a bound: " + "; ".join(report["on_bound"]))
    if report.get("outlier_cycles"):
        lines.append(f"outlier cycles ({'left out' if report['outliers'] == 'leave-out' else 'kept'}"
                     f"): " + "; ".join(c["note"] for c in report["outlier_cycles"]))
    half = report.get("half_strain")
    if half:
        for row, entry in zip(half["per_file"], report["files"]):
            lines.append(f"{row['file']} ({row['stress_MPa']:.4g} MPa): half-strain heating "
                         f"{row['data_heating_degC']:.2f} data / {row['model_heating_degC']:.2f} "
                         f"model degC, cooling {row['data_cooling_degC']:.2f} / "
                         f"{row['model_cooling_degC']:.2f} degC; transformation strain "
                         f"{100 * row['data_transformation_strain']:.3g} / "
                         f"{100 * row['model_transformation_strain']:.3g} %; strain RMS "
                         f"{entry['residual_rms']['strain']:.3g}")
            lines += [f"note: {row['file']}: {note}" for note in row.get("model_unfinished", [])]
        first = report["files"][0]
        per_mpa = first["load_kg"] / first["stress_MPa"] if first["stress_MPa"] else 0.0
        centres = [f"{name} {report['parameters'][name]['value'] * per_mpa:.4g}"
                   for name in ("b_h", "b_c", "b2_h", "b2_c") if name in report["parameters"]]
        if centres and not report.get("slopes_not_fitted"):
            where = " where s(sigma) has saturated" if "cc_share_h" in report["parameters"] else ""
            lines.append(f"fitted centre slopes{where} [K/MPa]: " + ", ".join(centres))
        slopes = half["slopes_K_per_MPa"]
        if np.isfinite(slopes["data"]["heating"]):
            lines.append(f"half-strain temperature against stress [K/MPa]: heating "
                         f"{slopes['data']['heating']:.4g} data, {slopes['model']['heating']:.4g} "
                         f"model; cooling {slopes['data']['cooling']:.4g} data, "
                         f"{slopes['model']['cooling']:.4g} model")
    for entry in report.get("hysteresis", []):
        def told(key):
            value = entry[key]
            return f"{value:.3g} K" if value is not None else "n/a"
        reasons = dict.fromkeys(reason for key in ("thermocouple_K", "wire_K")
                                if entry[key] is None
                                for reason in entry[f"{key}_why_missing"].split("; "))
        # e.g. a file of one cooling, then one heating branch holds no cycle with both:
        # "heating, cooling: no such branch ...", each reason once with the branches it names
        named = {}
        for reason in reasons:
            branch, colon, text = reason.partition(": ")
            if colon and branch in ("heating", "cooling"):
                named.setdefault(text, []).append(branch)
            else:
                named.setdefault(reason, [])
        why = (" (n/a: " + "; ".join(f"{', '.join(b)}: {t}" if b else t
                                     for t, b in named.items()) + ")") if reasons else ""
        lines.append(f"{entry['file']}: thermal hysteresis (median over cycles) "
                     f"{told('thermocouple_K')} at the thermocouple, {told('wire_K')} at the "
                     f"wire (model){why}")
    for entry in report["files"]:
        if entry["lag"]:
            lag = entry["lag"]
            lines.append(f"{Path(entry['file']).name}: lag {lag['value']:.4g} +- "
                         f"{lag['std_error']:.2g} {lag['unit']} ({lag['note']})")
    lines += _table([(name, f"{row['value']:.6g}", f"{row['std_error']:.3g}")
                     for name, row in report["parameters"].items()],
                    ("parameter", "value", "std error"))
    for load, centre in report["hysteresis_centres_degC"].items():
        lines.append(f"centres at {load}: heating {centre['heating']['value']:.2f} +- "
                     f"{centre['heating']['std_error']:.2f} degC, cooling "
                     f"{centre['cooling']['value']:.2f} +- {centre['cooling']['std_error']:.2f} degC")
    return "\n".join(lines)
