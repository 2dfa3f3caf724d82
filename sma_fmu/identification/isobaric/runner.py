"""``sma-fmu fit isobaric``: read isobaric files, fit, and write the results in one go.

Writes into ``out_dir``: ``identified.toml`` (a complete wire parameter file, ready for
``sma-fmu build --model`` and scenarios), ``report.json`` (estimates, standard errors,
covariance), ``transformation_temperatures.md`` and ``.csv`` (per cycle, data and model)
and PNG figures. Everything is computed first; nothing is written when reading, checking
or fitting fails.
"""
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
from scipy import stats

from sma_fmu.identification.coverage import DATA_RANGE_MEANINGS, coverage_header, with_coverage
from sma_fmu.identification.isobaric.fit import LAG_OPTIONS, RESIDUAL_OPTIONS, fit_isobaric
from sma_fmu.identification.isobaric.summary import format_isobaric_report, half_strain_table
from sma_fmu.identification.isobaric.cycles import parse_cycles, splitting_note
from sma_fmu.identification.isobaric.figures import isobaric_figures
from sma_fmu.identification.isobaric.files import read_isobaric
from sma_fmu.identification.isobaric.resolution import smooth_note
from sma_fmu.identification.isobaric.synthetic import load_of_stress, stress_of_load
from sma_fmu.identification.isobaric.tables import cycle_rows, rows_csv, rows_markdown
from sma_fmu.identification.isobaric.centre_law import centre_gradient, law_note
from sma_fmu.files.json_output import json_text
from sma_fmu.files.output_folder import check_folder, staged_folder
from sma_fmu.wire.parameter_file import load_parameter_set, write_parameter_file
from sma_fmu.runtime.constant_load import domain_energy, hysteresis_centre
from sma_fmu.runtime.constants import BOLTZMANN, COOLING, HEATING, KELVIN_OFFSET

__all__ = ["file_loads", "isobaric_report", "run_isobaric_fit", "format_isobaric_report",
           "TERM_MEANINGS"]

TERM_MEANINGS = {
    "nu_h": "cells per cooperative domain on heating (sets the heating transition width)",
    "nu_c": "cells per cooperative domain on cooling (sets the cooling transition width)",
    "w2": "share of the transformable fraction that transforms in the second stage",
    "a2_h": "second-stage heating centre at no load", "b2_h": "its load slope",
    "a2_c": "second-stage cooling centre at no load", "b2_c": "its load slope",
    "nu2_h": "second-stage domain size on heating", "nu2_c": "second-stage domain size on cooling",
    "alpha_P": "linear thermal expansion of the P phase",
    "alpha_MF": "linear thermal expansion of the M and F phases",
    "span_ratio_0": "transformation-strain factor s at no stress (s = 1 at saturation)",
    "span_stress": "stress scale of the transformation-strain law s(sigma)",
    "cc_share_h": "share of the heating centres' load slope that follows s(sigma) "
                  "(Clausius-Clapeyron; 0: linear centres)",
    "cc_share_c": "share of the cooling centres' load slope that follows s(sigma) "
                  "(Clausius-Clapeyron; 0: linear centres)"}


def file_loads(files, loads=None, stresses=None, diameter=None):
    """Load [kg] per file from ``--load`` or ``--stress`` values (one for all, or one per file).

    None per file means: from the file's header.
    """
    if loads and stresses:
        raise ValueError("give --load or --stress, not both")
    values, option = (loads, "--load") if loads else (stresses, "--stress")
    if not values:
        return [None] * len(files)
    if len(values) not in (1, len(files)):
        raise ValueError(f"{option} has {len(values)} values for {len(files)} files; give one for "
                         f"all files or one per file")
    values = list(values) * len(files) if len(values) == 1 else list(values)
    for value in values:
        if not value >= 0:
            raise ValueError(f"{option} {value!r}: must be >= 0")
    return values if loads else [load_of_stress(s, diameter) for s in values]


def _centres(fit, loads):
    """Hysteresis centres [degC] at each load, with standard errors from the covariance."""
    out = {}
    for load in loads:
        entry = {}
        for direction, sign in (("heating", HEATING), ("cooling", COOLING)):
            gradient = centre_gradient(load, sign, fit.params, fit.names)
            value = hysteresis_centre(load, sign, fit.params)
            error = float(np.sqrt(gradient @ fit.covariance @ gradient))
            entry[direction] = {"value": value, "std_error": error}
        out[f"{load:g} kg"] = entry
    return out


def _lag_note(lag):
    """What the lag is and in which unit (and, with a time column, how even its steps are)."""
    if lag["unit"] == "samples":
        return "wire behind the thermocouple, first-order lag; no time column, so counted in samples"
    note = f"wire behind the thermocouple, first-order lag; median time step {lag['step']:.4g} s"
    if lag["step_spread"] > 0.01:
        note += (f", steps differ from it by up to {100 * lag['step_spread']:.3g} % (the lag is "
                 f"computed on the median step)")
    return note


def isobaric_report(files, fit, base_set, residual, rows, outliers="leave-out"):
    """The JSON-ready report of an isobaric fit."""
    halfway = half_strain_table(files, fit)
    params = fit.params
    half = stats.t.ppf(0.975, fit.dof)
    loads = sorted({d.load for d in files})
    parameters = {
        name: {"value": float(v), "std_error": float(e), "ci95": [float(v - half * e), float(v + half * e)]}
        for name, v, e in zip(fit.wire_names, fit.wire_values, fit.wire_std_errors)}
    unknowns = {name: {"value": float(v), "std_error": float(e), "start": float(s)}
                for name, v, e, s in zip(fit.names, fit.values, fit.std_errors, fit.starts)}
    fixed = ["eps_T", "xi_F_inf", "f_F"] + [n for n in ("b_h", "b_c", "x_min", "R_P", "R_M", "R_F",
                                                        "T_alpha", "span_ratio_sat",
                                                        "span_stress", "cc_share_h",
                                                        "cc_share_c")
                                          if n not in fit.wire_names]
    per_file = []
    for data, offsets, sigma, floors, lag, knots, rms_of_file, parts in zip(
            files, fit.offsets, fit.sigma, fit.floors, fit.lags, fit.knots_per_branch,
            fit.file_rms, fit.strain_parts):
        per_file.append({
            "file": str(data.path), "load_kg": data.load,
            "cycles_found": splitting_note(data.splitting, data.branches, data.time is not None),
            "lag": lag and dict(lag, note=_lag_note(lag)),
            "profile_knots_per_branch": knots,
            "stress_MPa": stress_of_load(data.load, params.diameter),
            "points": int(data.strain.size),
            "columns": {q: list(v) for q, v in data.columns.items()},
            "strain_column_note": data.strain_note,
            "stress_column_MPa": data.stress_column,
            "reference_length_m": data.reference_length,
            "reference_length_source": data.reference_source,
            "reading_notes": data.notes,
            "branches": len(data.branches),
            "cycles": len({b.cycle for b in data.branches if b.complete}),
            "noise_estimates": sigma,
            "noise_floors": floors,
            "resolution": data.resolution,
            "residual_rms": rms_of_file,
            "strain_residual_parts": parts,
            "strain_offsets_per_level": offsets,
            "residual_strain_per_cycle": list(np.diff(offsets)) if residual == "per-cycle" else []})
    widths = {}
    for load in loads:
        centre_K = hysteresis_centre(load, HEATING, params) + KELVIN_OFFSET
        entry = {}
        for word, nu in (("heating", params.terms.nu_h), ("cooling", params.terms.nu_c)):
            energy = domain_energy(load, params, nu)
            entry[f"dH_J_{word}"] = energy
            entry[f"width_25_75_K_{word}"] = 2 * np.log(3) * BOLTZMANN * centre_K ** 2 / energy
        widths[f"{load:g} kg"] = entry
    return {
        "experiment": "isobaric",
        "files": per_file,
        "points": int(sum(d.strain.size for d in files)),
        "residual_strain_model": residual,
        "parameters": parameters,
        "covariance": {"parameters": list(fit.wire_names),
                       "matrix": [[float(v) for v in r] for r in fit.wire_covariance]},
        "unknowns": unknowns,
        "unknowns_covariance": {"parameters": list(fit.names),
                                "matrix": [[float(v) for v in r] for r in fit.covariance]},
        "hysteresis_centres_degC": _centres(fit, loads),
        "transition": widths,
        "fixed_from_base": {name: getattr(params.terms, name, None) if getattr(params, name) is None
                            else getattr(params, name) for name in fixed},
        "stages": fit.stages,
        "stage_note": fit.stage_note,
        "slopes_not_fitted": fit.slope_notes,
        "on_bound": fit.on_bound,
        "undetermined": {"unknowns": fit.undetermined,
                         "note": "touched by no residual (the strain levels of left-out cycles): "
                                 "kept at their starting values, standard error reported as 0"},
        "outlier_cycles": [{k: v for k, v in c.items() if k != "name"} | {"note": c["name"]}
                           for c in fit.outlier_cycles],
        "outliers": outliers,
        "half_strain": halfway,
        "centre_slopes_K_per_MPa": {
            name: float(getattr(params, name) if getattr(params, name) is not None
                        else getattr(params.terms, name)) * load_of_stress(1.0, params.diameter)
            for name in ("b_h", "b_c") + (("b2_h", "b2_c") if params.terms.two_stage else ())},
        "residual_rms": fit.residual_rms,
        "noise_estimates": fit.noise_estimates,
        "noise_floors": fit.noise_floors,
        "noise_judged": fit.noise,
        "noise_floor_notes": fit.floor_notes,
        "noise_smooth_note": smooth_note(fit.noise, fit.residual_rms),
        "verdict": fit.verdict,
        "variance_factor": fit.variance_factor,
        "degrees_of_freedom": fit.dof,
        "temperature_profile_unknowns": fit.profile_unknowns,
        "transformation_temperatures": rows,
        "base_parameter_file": str(base_set.path),
        "solver": {"converged": fit.converged, "message": fit.message,
                   "evaluations": fit.evaluations, "seconds": fit.seconds,
                   "first_fit": fit.first_fit,
                   "note": "first fit: the parameters at the thermocouple's own temperature "
                           "profile (chooses widths, stages, outliers, the lag's start); then "
                           "the joint fit with the profile's knots, whose convergence is the "
                           "verdict's"},
    }


def hysteresis_report(data, fit, rows):
    """Per file: the thermal hysteresis (heating minus cooling temperature at half the
    actuation strain, median over the cycles) at the thermocouple (the data against the
    measured temperature) and at the wire (the fitted model), and how much a lag of one
    unit would narrow the wire's."""
    out = []
    for d in data:
        mine = [r for r in rows if r["file"] == d.path.name and r["load_kg"] == d.load
                and r["quantity"] == "thermal_hysteresis"]
        entry = {"file": d.path.name}
        for key, source in (("thermocouple_K", "data"), ("wire_K", "model")):
            values = [r[source] for r in mine if np.isfinite(r[source])]
            entry[key] = float(np.median(values)) if values else None
            if not values:      # why, from the cycles' own notes (each reason once)
                reasons = dict.fromkeys(r[f"{source}_note"] for r in mine if r[f"{source}_note"])
                entry[f"{key}_why_missing"] = "; ".join(reasons) or "no cycle in the file"
        out.append(entry)
    for entry, sensor in zip(out, fit.sensor):
        entry["narrowing_K_per_lag_unit"] = sensor["narrowing"]
        if sensor["narrowing"] is None or not np.isfinite(sensor["narrowing"]):
            entry["narrowing_K_per_lag_unit"] = None
            entry["note"] = ("how much a lag would narrow the wire's hysteresis is not known: "
                             "no cycle holds a heating and a cooling ramp to take their rates "
                             "from")
            continue
        entry["note"] = (f"a lag of 1 {sensor['unit'].rstrip('s')} of the wire behind the "
                         f"thermocouple would make the wire's hysteresis about "
                         f"{sensor['narrowing']:.3g} K narrower than the thermocouple's (the "
                         f"heating and cooling ramp rates, summed)")
    return out


def run_isobaric_fit(files, out_dir, loads=None, stresses=None, model=None, residual="per-cycle",
                     reference_length=None, progress=lambda text: None, cycles=None, lag="auto",
                     stages=2, outliers="leave-out", widths="auto", meter=None,
                     centre_law="linear", renames=None):
    """Fit isobaric ``files``; write identified.toml, report.json, tables, figures; return report.

    ``cycles``: the text of ``--cycles`` (``5:``, ``3:10``, ``:20``, ``4``) or None for all;
    ``lag``: "auto", "fit" (the wire's lag behind the thermocouple) or "none"; ``meter``: a
    callable returning a tqdm-like progress bar (or None); ``centre_law``: "linear" or
    "clausius-clapeyron" (:func:`~.fit.fit_isobaric`); ``renames``: [(new, old)] columns read
    under another name (``--column``). A fit that did not converge is
    written too, marked so in identified.toml's header and report.json's ``solver``.
    """
    if not files:
        raise ValueError("no measurement file given")
    if residual not in RESIDUAL_OPTIONS:
        raise ValueError(f"--residual-strain must be one of {', '.join(RESIDUAL_OPTIONS)}, "
                         f"got {residual!r}")
    if lag not in LAG_OPTIONS:
        raise ValueError(f"--lag must be one of {', '.join(LAG_OPTIONS)}, got {lag!r}")
    selection = parse_cycles(cycles) if cycles is not None else None
    check_folder(out_dir)
    base_set = load_parameter_set(model)
    base = base_set.params
    reference = base.x0 if reference_length is None else reference_length
    source = "--reference-length" if reference_length is not None else \
        f"x0 of {Path(base_set.path).name}"
    per_file = file_loads(files, loads, stresses, base.diameter)
    data = [read_isobaric(Path(f), load, reference, base.diameter, selection, source, base.x0,
                          renames)
            for f, load in zip(files, per_file)]
    for d in data:
        for note in d.notes:
            progress(f"{d.path.name}: {note}")
        progress(f"{d.path.name}: {splitting_note(d.splitting, d.branches, d.time is not None)}")
    progress(f"fitting {len(data)} file(s), {sum(d.strain.size for d in data)} points ...")
    fit = fit_isobaric(data, base, residual, lag, stages=stages, outliers=outliers,
                       widths=widths, meter=meter, centre_law=centre_law)
    progress("transformation temperatures and figures ...")
    per_cycle = residual == "per-cycle"
    rows = [row for d, offsets, profile, bounds in zip(data, fit.offsets, fit.profiles,
                                                       fit.wire_bounds)
            for row in cycle_rows(d, fit.params, offsets, profile, per_cycle, bounds)]
    top = max(stress_of_load(d.load, base.diameter) for d in data)
    hottest = max(float(d.temperature.max()) for d in data)
    if top > fit.params.stress_max:    # the fitted model is valid as far as its data go
        fit.params = fit.params.replace(stress_max=float(np.ceil(top)))
    if hottest > fit.params.T_max:
        fit.params = fit.params.replace(T_max=float(np.ceil(hottest)))
    fit.params, covered = with_coverage(   # the data range; what the data did not determine
        fit.params, base_set, fit.wire_names,
        [t for d in data for t in (d.temperature.min(), d.temperature.max())],
        [stress_of_load(d.load, base.diameter) for d in data])
    report = isobaric_report(data, fit, base_set, residual, rows, outliers)
    report["coverage"] = covered
    report["lag_choice"] = {"option": fit.lag_option, "note": fit.lag_note}
    report["hysteresis"] = hysteresis_report(data, fit, rows)
    report["centre_law"] = law_note(centre_law, fit.params, len({d.load for d in data}),
                                    "cc_share_h" in fit.wire_names)
    figures = isobaric_figures(data, fit, per_cycle, rows)
    stamp = datetime.now(timezone.utc).isoformat(timespec="seconds")
    names = ", ".join(Path(f).name for f in files)
    verdict = [] if fit.converged else [
        f"NOT CONVERGED: the solver stopped after {fit.evaluations} evaluations: {fit.message}; "
        f"the values below are where it stopped, not a fit"]
    with staged_folder(out_dir) as folder:
        write_parameter_file(
            folder / "identified.toml", fit.params, f"{base_set.name}-isobaric",
            f"isobaric fit of {names}; strain RMS {fit.residual_rms['strain']:.3g}"
            + ("" if fit.converged else " (not converged)"),
            {**TERM_MEANINGS, **(base_set.meanings or {}), **DATA_RANGE_MEANINGS},
            header=verdict + [
                f"Identified by sma-fmu fit isobaric on {stamp}.",
                f"Fitted: {', '.join(fit.wire_names)}; everything else from {base_set.path}"
                f" (validity.stress_max and T_max raised to the largest fitted stress and "
                f"temperature where they were lower).",
                *fit.slope_notes,
                coverage_header(covered),
                f"Data: {', '.join(str(f) for f in files)} at "
                f"{', '.join(f'{d.load:g}' for d in data)} kg"])
        (folder / "report.json").write_text(json_text(report), encoding="utf-8")
        (folder / "transformation_temperatures.csv").write_text(rows_csv(rows), encoding="utf-8")
        (folder / "transformation_temperatures.md").write_text(rows_markdown(rows), encoding="utf-8")
        for name, png in figures.items():
            (folder / name).write_bytes(png)
    return report
