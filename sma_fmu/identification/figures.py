"""Fit figures: data vs model like the paper's Figs. 4-6, and residuals; returned as PNG bytes.

Drawn on :class:`matplotlib.figure.Figure` objects (no pyplot, no backend switch).
"""
import numpy as np
from matplotlib.figure import Figure

from sma_fmu.files.png_output import png_bytes
from sma_fmu.runtime.constant_load import constant_load_resistance
from sma_fmu.runtime.sensing import sense_temperature

__all__ = ["constant_load_figures", "constant_temperature_figures", "BRANCH_STYLE"]

BRANCH_STYLE = {1: ("tab:red", "heating"), -1: ("tab:blue", "cooling")}  # direction: colour, label


def _png(figure):
    return png_bytes(figure, dpi=100, tight=True)


def _load_grid(count):
    columns = min(count, 2)
    rows = int(np.ceil(count / columns))
    figure = Figure(figsize=(6 * columns, 4 * rows))
    axes = figure.subplots(rows, columns, squeeze=False)
    for axis in axes.flat[count:]:
        axis.set_visible(False)
    return figure, axes.flat


def constant_load_figures(params, data, sensed):
    """{file name: PNG bytes}: data vs model (Fig. 4), sensing (Fig. 5), residuals."""
    loads = sorted(set(data.load.tolist()))
    grid = np.linspace(data.temperature.min(), data.temperature.max(), 400)
    model_figure, model_axes = _load_grid(len(loads))
    sense_figure, sense_axes = _load_grid(len(loads))
    residual_figure, residual_axes = _load_grid(len(loads))
    for load, model_axis, sense_axis, residual_axis in zip(loads, model_axes, sense_axes, residual_axes):
        for direction, (colour, label) in BRANCH_STYLE.items():
            rows = (data.load == load) & (data.direction == direction)
            curve = [constant_load_resistance(t, load, direction, params) for t in grid]
            model_axis.plot(data.temperature[rows], data.resistance[rows], ".", ms=3, color=colour,
                            alpha=0.6, label=f"data, {label}")
            model_axis.plot(grid, curve, color=colour, lw=1.2, label=f"model, {label}")
            r_grid = np.linspace(min(curve), max(curve), 400)[1:-1]
            inverse = [sense_temperature(r, load, direction, params).temperature for r in r_grid]
            sense_axis.plot(data.resistance[rows], data.temperature[rows], ".", ms=3, color=colour,
                            alpha=0.6, label=f"data, {label}")
            sense_axis.plot(r_grid, inverse, color=colour, lw=1.2, label=f"sensing model, {label}")
            model_at_rows = np.array([constant_load_resistance(t, load, direction, params)
                                      for t in data.temperature[rows]])
            residual_axis.plot(data.temperature[rows], model_at_rows - data.resistance[rows], ".",
                               ms=3, color=colour, label=label)
        model_axis.set(title=f"load {load:g} kg", xlabel="temperature [degC]", ylabel="resistance [ohm]")
        sense_axis.set(title=f"load {load:g} kg: temperature from resistance",
                       xlabel="resistance [ohm]", ylabel="temperature [degC]")
        residual_axis.set(title=f"load {load:g} kg", xlabel="temperature [degC]",
                          ylabel="model - data [ohm]")
        for axis in (model_axis, sense_axis, residual_axis):
            axis.grid(alpha=0.3)
            axis.legend(fontsize=7)
    return {"fit_resistance_temperature.png": _png(model_figure),
            "fit_temperature_sensing.png": _png(sense_figure),
            "fit_residuals.png": _png(residual_figure)}


def constant_temperature_figures(params, experiments, model):
    """{file name: PNG bytes}: resistance against load (Fig. 6) with the model, and residuals."""
    figure = Figure(figsize=(8, 7))
    top, bottom = figure.subplots(2, 1, sharex=True)
    offset = 0
    for e in experiments:
        rows = slice(offset, offset + e.load.size)
        offset += e.load.size
        top.plot(e.load, e.resistance, ".", ms=3, alpha=0.6, label=f"data, {e.temperature:.1f} degC")
        top.plot(e.load, model[rows], lw=1.0, label=f"model, {e.temperature:.1f} degC")
        bottom.plot(e.load, model[rows] - e.resistance, ".", ms=3, label=e.path.name)
    top.set(ylabel="resistance [ohm]", title="load cycle at constant temperature")
    bottom.set(xlabel="load [kg]", ylabel="model - data [ohm]")
    for axis in (top, bottom):
        axis.grid(alpha=0.3)
        axis.legend(fontsize=7)
    return {"fit_resistance_load.png": _png(figure)}
