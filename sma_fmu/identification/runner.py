"""``sma-fmu fit``: read measurement files, identify parameters, write the results.

Writes into ``out_dir``: ``identified.toml`` (a complete parameter file in the format of
``models/``, ready for the FMUs and scenarios, with the range its data covered),
``report.json`` (with that range, the diameter of every MPa <-> kg and what the fit did not
determine: :mod:`.coverage`) and PNG figures. All of it is computed first; nothing is
written when reading, checking or fitting fails.
"""
from datetime import datetime, timezone
from pathlib import Path

from sma_fmu.identification import constant_load as fit_constant_load
from sma_fmu.identification import constant_temperature as fit_constant_temperature
from sma_fmu.identification.coverage import (DATA_RANGE_MEANINGS, coverage_header,
                                             coverage_lines, stress_of_load, with_coverage)
from sma_fmu.identification.figures import constant_load_figures, constant_temperature_figures
from sma_fmu.identification.measurements import read_constant_load, read_constant_temperature
from sma_fmu.files.json_output import json_text
from sma_fmu.files.output_folder import staged_folder
from sma_fmu.wire.parameter_file import load_parameter_set, parameter_file_text

__all__ = ["EXPERIMENTS", "run_fit", "format_report"]

EXPERIMENTS = ("constant-load", "constant-temperature")


def _fit(experiment, files, base, progress):
    """(FitResult, report, {figure name: PNG bytes}, (temperatures [degC], loads [kg]) the
    data cover, or None where they do not set the data range) of one experiment."""
    if experiment == "constant-load":
        data = read_constant_load(files)
        kept = fit_constant_load.kept_from_base(base)
        progress(f"fitting {len(fit_constant_load.FITTED) - len(kept)} parameters to "
                 f"{data.resistance.size} points ...")
        result, report = fit_constant_load.fit_constant_load(data, base)
        progress("drawing the figures ...")
        sensed, _, _ = fit_constant_load.sensing_comparison(result.params, data)
        return (result, report, constant_load_figures(result.params, data, sensed),
                (data.temperature, data.load))
    experiments = [read_constant_temperature(f) for f in files]
    progress(f"fitting {len(fit_constant_temperature.FITTED)} parameters to "
             f"{sum(e.load.size for e in experiments)} points ...")
    result, report = fit_constant_temperature.fit_constant_temperature(experiments, base)
    progress("drawing the figures ...")
    model = fit_constant_temperature.model_resistance(result.params, experiments)
    # eps_f, nu_f (the stress-induced transformation at one temperature) are not in the
    # plant or the compensator: their data leave the FMUs' data range as the base gave it
    return result, report, constant_temperature_figures(result.params, experiments, model), None


def run_fit(experiment, files, out_dir, model=None, progress=lambda text: None):
    """Identify from ``files``; write identified.toml, report.json and figures; return report."""
    if experiment not in EXPERIMENTS:
        raise ValueError(f"experiment must be one of {', '.join(EXPERIMENTS)}, got {experiment!r}")
    if not files:
        raise ValueError("no measurement file given")
    base_set = load_parameter_set(model)
    result, report, figures, spans = _fit(experiment, [Path(f) for f in files],
                                          base_set.params, progress)
    fitted = [p.name for p in result.parameters]
    stamp = datetime.now(timezone.utc).isoformat(timespec="seconds")
    report["base_parameter_file"] = str(base_set.path)
    temperatures, loads = spans or (None, [])
    params, report["coverage"] = with_coverage(
        result.params, base_set, fitted, temperatures,
        [stress_of_load(float(load), base_set.params.diameter) for load in loads])
    text = parameter_file_text(
        params, f"{base_set.name}-identified",
        f"{experiment} fit of {', '.join(Path(f).name for f in files)}; MAPE "
        f"{report['mape_percent']:.3g} %", {**base_set.meanings, **DATA_RANGE_MEANINGS},
        header=[f"Identified by sma-fmu fit {experiment} on {stamp}.",
                f"Fitted: {', '.join(fitted)}; everything else from {base_set.path}.",
                coverage_header(report["coverage"]),
                f"Data: {', '.join(str(f) for f in files)}"])
    with staged_folder(out_dir) as folder:
        (folder / "identified.toml").write_text(text, encoding="utf-8")
        (folder / "report.json").write_text(json_text(report), encoding="utf-8")
        for name, png in figures.items():
            (folder / name).write_bytes(png)
    return report


def format_report(report):
    """A short text summary of a fit report."""
    lines = [f"{report['experiment']} fit: {report['points']} points, MAPE "
             f"{report['mape_percent']:.3f} %, max |error| {report['max_abs_error_ohm']:.4g} ohm, "
             f"{report['solver']['seconds']:.3f} s ({report['solver']['evaluations']} evaluations)",
             f"{'parameter':<12}{'value':>14}{'std error':>12}{'start':>14}"]
    for name, row in report["parameters"].items():
        flag = "  (at bound)" if row["at_bound"] else ""
        lines.append(f"{name:<12}{row['value']:>14.6g}{row['std_error']:>12.3g}{row['start']:>14.6g}{flag}")
    sensing = report.get("temperature_sensing")
    if sensing:
        core = sensing["core_5_95_percent"]
        lines.append(f"temperature sensing (5-95 % of the transformation): {core['points']} points, "
                     f"RMSE {core['rmse_K']:.3g} K, max {core['max_abs_K']:.3g} K")
    if report.get("kept_from_base"):
        lines.append(report["kept_from_base"]["note"])
    if "coverage" in report:
        lines += coverage_lines(report)
    return "\n".join(lines)
