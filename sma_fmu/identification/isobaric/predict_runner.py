"""``sma-fmu predict isobaric FILE --model PARAMS [--stress MPA | --load KG] --out DIR``.

Writes into DIR: ``predicted.csv`` (temperature fed [degC], measured and predicted strain
[1] per sample, offset-matched and from the model's own zero), ``report.json``
(``residual_rms``: both strain RMS; the tangent-line and half-strain temperatures of both,
how the plant was driven) and ``predict_isobaric.png`` (strain against
temperature, measured and predicted, and the residual against sample). Everything is
computed first; a failure leaves DIR as it was.
"""
import math
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from sma_fmu.files.json_output import json_text
from sma_fmu.files.output_folder import check_folder, staged_folder
from sma_fmu.files.png_output import png_bytes
from sma_fmu.identification.isobaric.files import read_isobaric
from sma_fmu.identification.isobaric.missing import Reasons
from sma_fmu.identification.isobaric.predict import predict_file
from sma_fmu.identification.isobaric.synthetic import load_of_stress
from sma_fmu.runtime.constants import HEATING
from sma_fmu.wire.parameter_file import load_parameter_set

__all__ = ["run_isobaric_predict", "format_predict_report"]

DENSE_ROWS = 2000   # a file with fewer rows draws its measured points large and opaque


def _figure(data, result):
    figure = Figure(figsize=(11, 4.2))
    left, right = figure.subplots(1, 2)
    t = data.smoothed
    # a dense file's points as a faint cloud, a sparse one's (tens of rows) as clear dots
    sparse = t.size < DENSE_ROWS
    for b in data.branches:
        rows = slice(b.start, b.stop)
        colour = "tab:red" if b.direction == HEATING else "tab:blue"
        left.plot(t[rows], 100 * result["measured"][rows], ".", ms=5 if sparse else 2,
                  color=colour, alpha=0.9 if sparse else 0.35)
        left.plot(t[rows], 100 * result["predicted"][rows], "-", lw=1.2, color="k"
                  if b.direction == HEATING else "0.45")
        left.plot(t[rows], 100 * result["own_zero"][rows], ":", lw=0.8, color="tab:purple")
    left.plot([], [], ".", color="tab:red", label="measured, heating")
    left.plot([], [], ".", color="tab:blue", label="measured, cooling")
    left.plot([], [], "-", color="k", label="predicted (plant runtime), offset-matched, heating")
    left.plot([], [], "-", color="0.45", label="predicted, offset-matched, cooling")
    left.plot([], [], ":", color="tab:purple", label="predicted from the model's own zero")
    report = result["report"]
    rms = report["residual_rms"]
    left.set(title=f"{data.path.name}, {report['stress_MPa']:.4g} MPa\nstrain RMS "
                   f"{rms['strain']:.3g} offset-matched, {rms['strain_own_zero']:.3g} own zero",
             xlabel="measured temperature (smoothed) [degC]", ylabel="strain [%]")
    # below the axes: inside, it hides the transformation or the own-zero curve
    left.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)
    sample = data.time if data.time is not None else np.arange(data.strain.size)
    right.plot(sample, 100 * (result["predicted"] - result["measured"]), ".", ms=4 if sparse else 1.5)
    right.set(title="predicted (offset-matched) - measured", xlabel="time [s]"
              if data.time is not None else "sample", ylabel="strain [%]")
    for axis in (left, right):
        axis.grid(alpha=0.3)
    return png_bytes(figure, dpi=90, tight=True)


def _csv(result):
    lines = ["temperature_C,strain_measured,strain_predicted,strain_predicted_own_zero"]
    for t, m, p, z in zip(result["temperature"], result["measured"], result["predicted"],
                          result["own_zero"]):
        lines.append(f"{t:.6f},{m:.9g},{p:.9g},{z:.9g}")
    return "\n".join(lines) + "\n"


def run_isobaric_predict(path, out_dir, model, load=None, stress=None, reference_length=None,
                         lag=0.0, renames=None):
    """Predict one file's strain with the plant runtime; write the outputs; return the report
    (``renames``: [(new, old)] columns read under another name, ``--column``)."""
    if load is not None and stress is not None:
        raise ValueError("predict: give --load or --stress, not both")
    check_folder(out_dir)
    params_set = load_parameter_set(model)
    params = params_set.params
    if stress is not None:
        load = load_of_stress(stress, params.diameter)
    reference = params.x0 if reference_length is None else reference_length
    source = "--reference-length" if reference_length is not None else \
        f"x0 of {Path(params_set.path).name}"
    data = read_isobaric(Path(path), load, reference, params.diameter, reference_source=source,
                         model_length=params.x0, renames=renames)
    result = predict_file(data, params, lag)
    report = dict(result["report"], model=str(params_set.path),
                  reference_length_m=data.reference_length, reference_length_source=source,
                  reading_notes=data.notes)
    if data.load > params.load_max:   # the FMU warns there too, and runs on
        report["warning"] = (f"load {data.load:.4g} kg is above the model's validity limit "
                             f"{params.load_max:.4g} kg (validity.stress_max of "
                             f"{params_set.path})")
    png = _figure(data, result)
    with staged_folder(out_dir) as folder:
        (folder / "report.json").write_text(json_text(report), encoding="utf-8")
        (folder / "predicted.csv").write_text(_csv(result), encoding="utf-8")
        (folder / "predict_isobaric.png").write_bytes(png)
    return report


def format_predict_report(report):
    """A short text summary of a predict report."""
    tt = report["transformation_temperatures"]
    lines = [f"predict isobaric: {Path(report['file']).name}, {report['points']} points at "
             f"{report['stress_MPa']:.4g} MPa ({report['load_kg']:.4g} kg); plant runtime "
             f"{report['drive']['seconds']:.2f} s",
             f"strain residual RMS {report['residual_rms']['strain']:.3g} offset-matched (the "
             f"prediction shifted by {report['strain_offset']:.3g}, the median difference to the "
             f"measured strain: a lab's strain zero is its own)",
             f"strain residual RMS {report['residual_rms']['strain_own_zero']:.3g} from the "
             f"model's own zero (length / {report['reference_length_m']:g} m - 1, unshifted)",
             f"{'':<20}{'measured':>10}{'predicted':>11}{'difference':>12}"]
    why, reasons = tt.get("why_missing", {}), Reasons()
    for key, label, scale in [(k, f"{k} [degC]", 1.0) for k in ("A_s", "A_f", "M_s", "M_f",
                                                                "half_heating", "half_cooling")] \
            + [("transformation_strain", "strain span [%]", 100.0)]:
        cells = []
        for source in ("measured", "predicted"):
            value = tt[source][key]
            cells.append(f"{scale * value:.{2 if scale == 1.0 else 3}f}" if math.isfinite(value)
                         else reasons.mark(f"{source}: {why.get(source, {}).get(key, '')}"))
        difference = tt["predicted"][key] - tt["measured"][key]
        cells.append(f"{scale * difference:.{2 if scale == 1.0 else 3}f}"
                     if math.isfinite(difference) else "n/a")
        lines.append(f"{label:<20}{cells[0]:>10}{cells[1]:>11}{cells[2]:>12}")
    lines += reasons.lines()
    if report.get("warning"):
        lines.insert(1, f"warning: {report['warning']}")
    name = Path(report["file"]).name
    lines[1:1] = [f"{name}: {note}" for note in report.get("reading_notes", [])]
    return "\n".join(lines)
