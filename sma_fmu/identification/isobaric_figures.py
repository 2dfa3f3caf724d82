"""Figures of an isobaric fit (PNG bytes): strain against temperature per cycle, residuals.

Drawn on :class:`matplotlib.figure.Figure` objects (no pyplot, no backend switch).
Data points are drawn at the fitted wire temperature (the nuisance profile of the fit)
with the measured temperature faint behind them.
"""
import io

import numpy as np
from matplotlib.figure import Figure

from sma_fmu.identification.isobaric import file_model
from sma_fmu.identification.isobaric_tables import model_branch_strain
from sma_fmu.runtime.constants import HEATING

__all__ = ["isobaric_figures"]

_STYLE = {1: ("tab:red", "heating"), -1: ("tab:blue", "cooling")}
_MAX_POINTS = 4000   # per branch drawn (a 20,000-point file stays readable)


def _png(figure):
    buffer = io.BytesIO()
    figure.tight_layout()
    figure.savefig(buffer, format="png", dpi=90)
    return buffer.getvalue()


def _cycles(data):
    cycles = {}
    for b in data.branches:
        cycles.setdefault(b.cycle, []).append(b)
    return cycles


def isobaric_figures(files, fit, per_cycle=True):
    """{file name: PNG bytes}: fit_isobaric_cycles.png, fit_isobaric_residuals.png
    and, when a file has resistance, fit_isobaric_resistance.png."""
    columns = max(len(_cycles(d)) for d in files)
    cycles_figure = Figure(figsize=(4.2 * columns, 3.4 * len(files)))
    axes = cycles_figure.subplots(len(files), columns, squeeze=False)
    residual_figure = Figure(figsize=(10, 2.6 * 2 * len(files)))
    residual_axes = residual_figure.subplots(2 * len(files), 1, squeeze=False)[:, 0]
    with_r = [d for d in files if d.resistance is not None]
    r_figure = Figure(figsize=(6, 3.6 * max(1, len(with_r)))) if with_r else None
    r_axes = r_figure.subplots(len(with_r), 1, squeeze=False)[:, 0] if with_r else []
    r_index = 0
    for row, (data, profile, offsets) in enumerate(zip(files, fit.profiles, fit.offsets)):
        for column, (cycle, branches) in enumerate(sorted(_cycles(data).items())):
            axis = axes[row, column]
            for b in branches:
                colour, label = _STYLE[b.direction]
                step = max(1, (b.stop - b.start) // _MAX_POINTS)
                rows = slice(b.start, b.stop, step)
                axis.plot(data.temperature[rows], 100 * data.strain[rows], ".", ms=1.5,
                          color="0.8", zorder=1)
                axis.plot(profile[rows], 100 * data.strain[rows], ".", ms=2, color=colour,
                          alpha=0.5, label=f"data, {label}", zorder=2)
                grid = np.linspace(profile[b.start:b.stop].min(), profile[b.start:b.stop].max(), 400)
                axis.plot(grid, 100 * model_branch_strain(grid, b, data, fit.params, offsets,
                                                          per_cycle),
                          color="k" if b.direction == HEATING else "0.3", lw=1.0,
                          label=f"model, {label}", zorder=3)
            axis.set(title=f"{data.path.name}, {data.load:g} kg, cycle {cycle}",
                     xlabel="temperature [degC]", ylabel="strain [%]")
            axis.grid(alpha=0.3)
            axis.legend(fontsize=6)
        for axis in axes[row, len(_cycles(data)):]:
            axis.set_visible(False)
        sample = data.time if data.time is not None else np.arange(data.strain.size)
        strain, resistance = file_model(fit.params, data, profile, np.array(offsets))
        top, bottom = residual_axes[2 * row], residual_axes[2 * row + 1]
        top.plot(sample, 100 * (strain - data.strain), ".", ms=1.5)
        top.set(ylabel="model - data [% strain]", title=f"{data.path.name}: strain residuals")
        bottom.plot(sample, data.temperature - profile, ".", ms=1.5, color="tab:orange")
        bottom.set(xlabel="time [s]" if data.time is not None else "sample",
                   ylabel="measured - fitted [K]", title="temperature: measured minus fitted profile")
        for axis in (top, bottom):
            axis.grid(alpha=0.3)
        if resistance is not None:
            axis = r_axes[r_index]
            r_index += 1
            for direction, (colour, label) in _STYLE.items():
                rows = np.nonzero(data.row_direction == direction)[0]
                order = rows[np.argsort(profile[rows])]
                axis.plot(profile[order], data.resistance[order], ".", ms=2, color=colour,
                          alpha=0.4, label=f"data, {label}")
                axis.plot(profile[order], resistance[order], color="k", lw=0.8)
            axis.set(title=f"{data.path.name}: resistance", xlabel="fitted temperature [degC]",
                     ylabel="resistance [ohm]")
            axis.grid(alpha=0.3)
            axis.legend(fontsize=7)
    out = {"fit_isobaric_cycles.png": _png(cycles_figure),
           "fit_isobaric_residuals.png": _png(residual_figure)}
    if r_figure is not None:
        out["fit_isobaric_resistance.png"] = _png(r_figure)
    return out
