"""Figures of an isobaric fit (PNG bytes), readable from 2 to 200 cycles per file.

- ``fit_isobaric_cycles.png``: strain against the fitted wire temperature, data and model.
  Up to ``GRID_CYCLES`` cycles per file: one panel per cycle in a grid of at most four
  columns; more: one panel per file, every cycle overlaid and coloured by its number.
- ``fit_isobaric_stabilisation.png``: per-cycle A_s, A_f, M_s, M_f and residual strain
  against cycle number, data (markers) and model (lines): the stabilisation plot labs use;
  outlier cycles shaded grey.
- ``fit_isobaric_residuals.png``: strain and temperature residuals against sample or time,
  with their noise estimates.
- ``fit_isobaric_resistance.png`` when a file has resistance.

Drawn on :class:`matplotlib.figure.Figure` objects (no pyplot, no backend switch).
"""
import math

import numpy as np
from matplotlib import cm, colormaps, colors
from matplotlib.figure import Figure

from sma_fmu.files.png_output import png_bytes
from sma_fmu.identification.figures import BRANCH_STYLE
from sma_fmu.identification.isobaric.jacobian import file_model
from sma_fmu.identification.isobaric.tables import model_branch_strain
from sma_fmu.runtime.constants import HEATING

__all__ = ["isobaric_figures", "GRID_CYCLES"]

GRID_CYCLES = 12
_MAX_POINTS = 40000   # per file drawn in an overlay (every k-th sample beyond it)


def _png(figure):
    return png_bytes(figure, dpi=90, tight=True)


def _cycles(data):
    cycles = {}
    for index, b in enumerate(data.branches):
        cycles.setdefault(b.cycle, []).append((index, b))
    return cycles


def _model_line(axis, data, fit_file, index, b, colour, lw=1.0, label=None):
    wire, bounds, params, offsets, per_cycle = fit_file
    of = wire[bounds[index]:bounds[index + 1]]
    grid = np.linspace(of.min(), of.max(), 300)
    axis.plot(grid, 100 * model_branch_strain(grid, b, data, params, offsets, per_cycle),
              color=colour, lw=lw, label=label, zorder=3)


def _grid(files, fit, per_cycle):
    counts = [len(_cycles(d)) for d in files]
    columns = min(4, max(counts))
    panel_rows = [math.ceil(c / columns) for c in counts]
    figure = Figure(figsize=(3.8 * columns, 3.0 * sum(panel_rows)))
    axes = figure.subplots(sum(panel_rows), columns, squeeze=False)
    first_row = 0
    for data, wire, bounds, offsets, rows in zip(files, fit.profiles, fit.wire_bounds, fit.offsets,
                                                 panel_rows):
        fit_file = (wire, bounds, fit.params, offsets, per_cycle)
        cycles = sorted(_cycles(data).items())
        for k in range(rows * columns):
            axis = axes[first_row + k // columns, k % columns]
            if k >= len(cycles):
                axis.set_visible(False)
                continue
            cycle, branches = cycles[k]
            for index, b in branches:
                colour, label = BRANCH_STYLE[b.direction]
                of = slice(bounds[index], bounds[index + 1])
                axis.plot(wire[of], 100 * data.strain[of], ".", ms=2, color=colour, alpha=0.4,
                          label=f"data, {label}")
                _model_line(axis, data, fit_file, index, b,
                            "k" if b.direction == HEATING else "0.35", label=f"model, {label}")
            axis.set_title(f"{data.path.name}, cycle {cycle}", fontsize=9)
            axis.set(xlabel="wire temperature [degC]", ylabel="strain [%]")
            axis.grid(alpha=0.3)
            if k == 0:
                axis.legend(fontsize=6)
        first_row += rows
    return figure


def _overlay(files, fit, per_cycle):
    figure = Figure(figsize=(8.0, 5.2 * len(files)))
    axes = figure.subplots(len(files), 1, squeeze=False)[:, 0]
    for axis, data, wire, bounds, offsets in zip(axes, files, fit.profiles, fit.wire_bounds,
                                                 fit.offsets):
        fit_file = (wire, bounds, fit.params, offsets, per_cycle)
        cycles = sorted(_cycles(data).items())
        numbers = [c for c, _ in cycles]
        norm = colors.Normalize(min(numbers), max(numbers))
        cmap = colormaps["viridis"]
        step = max(1, data.strain.size // _MAX_POINTS)
        cycle_of = np.zeros(data.strain.size)
        for cycle, branches in cycles:
            for index, _ in branches:
                cycle_of[bounds[index]:bounds[index + 1]] = cycle
        axis.scatter(wire[::step], 100 * data.strain[::step], c=cycle_of[::step], cmap="viridis",
                     norm=norm, s=1.5, alpha=0.35, linewidths=0, rasterized=True)
        for cycle, branches in cycles:
            for index, b in branches:
                if b.complete:
                    _model_line(axis, data, fit_file, index, b, cmap(norm(cycle)), lw=0.6)
        bar = figure.colorbar(cm.ScalarMappable(norm=norm, cmap="viridis"), ax=axis)
        bar.set_label("cycle")
        axis.set(title=f"{data.path.name}, {data.load:g} kg: {len(cycles)} cycles (points: "
                       f"data, lines: model)", xlabel="wire temperature [degC]",
                 ylabel="strain [%]")
        axis.grid(alpha=0.3)
    return figure


def _stabilisation(files, rows, outliers=()):
    figure = Figure(figsize=(9.0, 6.4 * len(files)))
    axes = figure.subplots(2 * len(files), 1, squeeze=False)[:, 0]
    for k, data in enumerate(files):
        top, bottom = axes[2 * k], axes[2 * k + 1]
        odd = [c["cycle"] for c in outliers if c["file"] == str(data.path)]
        for axis in (top, bottom):
            for n, cycle in enumerate(odd):
                axis.axvspan(cycle - 0.5, cycle + 0.5, color="0.85", zorder=0,
                             label="outlier cycle" if n == 0 else None)
        mine = [r for r in rows if r["file"] == data.path.name and r["load_kg"] == data.load]
        for quantity, colour in (("A_s", "tab:orange"), ("A_f", "tab:red"), ("M_s", "tab:cyan"),
                                 ("M_f", "tab:blue")):
            these = [r for r in mine if r["quantity"] == quantity]
            cycle = [r["cycle"] for r in these]
            top.plot(cycle, [r["data"] for r in these], ".", ms=3, color=colour, alpha=0.35)
            top.plot(cycle, [r["data_wire"] for r in these], "o", ms=3, color=colour,
                     label=f"{quantity} data")
            top.plot(cycle, [r["model"] for r in these], "-", lw=1.2, color=colour,
                     label=f"{quantity} model")
        top.set_title(f"{data.path.name}: tangent-line temperatures per cycle (dots: at the wire "
                      f"temperature, faint: at the measured one)", fontsize=10)
        top.set(
                xlabel="cycle", ylabel="temperature [degC]")
        top.legend(fontsize=7, ncol=4)
        these = [r for r in mine if r["quantity"] == "residual_strain"]
        cycle = [r["cycle"] for r in these]
        bottom.plot(cycle, [r["data_wire"] for r in these], "o", ms=3, color="k",
                    label="data (wire temperature)")
        bottom.plot(cycle, [r["model"] for r in these], "-", color="tab:green", label="model")
        bottom.set(title="residual strain left by each cycle", xlabel="cycle",
                   ylabel="residual strain [%]")
        bottom.legend(fontsize=7)
        for axis in (top, bottom):
            axis.grid(alpha=0.3)
    return figure


def _residuals(files, fit):
    figure = Figure(figsize=(10, 5.2 * len(files)))
    axes = figure.subplots(2 * len(files), 1, squeeze=False)[:, 0]
    for k, (data, wire, measured, offsets, sigma) in enumerate(
            zip(files, fit.profiles, fit.measured_profiles, fit.offsets, fit.sigma)):
        sample = data.time if data.time is not None else np.arange(data.strain.size)
        strain, _ = file_model(fit.params, data, wire, offsets, fit.directions[k],
                               fit.row_levels[k], len(offsets) > 1)
        _residual_panel(axes[2 * k], sample, 100 * (strain - data.strain), 100 * sigma["strain"],
                        "tab:blue", ylabel="model - data [% strain]",
                        title=f"{data.path.name}: strain residuals (band: the noise estimate)")
        _residual_panel(axes[2 * k + 1], sample, data.temperature - measured, sigma["temperature"],
                        "tab:orange", xlabel="time [s]" if data.time is not None else "sample",
                        ylabel="measured - fitted [K]",
                        title="thermocouple temperature: measured minus fitted profile (before the lag)")
    return figure


def _residual_panel(axis, sample, residual, noise, colour, **labels):
    """Residuals against sample or time, with a band of +-``noise`` (the noise estimate)."""
    axis.plot(sample, residual, ".", ms=1, alpha=0.5, color=colour)
    axis.axhspan(-noise, noise, color="tab:green", alpha=0.2, label="noise estimate")
    axis.set(**labels)
    axis.legend(fontsize=7)
    axis.grid(alpha=0.3)


def _resistance(files, fit):
    with_r = [k for k, d in enumerate(files) if d.resistance is not None]
    figure = Figure(figsize=(6, 3.6 * len(with_r)))
    axes = figure.subplots(len(with_r), 1, squeeze=False)[:, 0]
    for axis, k in zip(axes, with_r):
        data, wire, direction = files[k], fit.profiles[k], fit.directions[k]
        level = np.zeros(wire.size, dtype=int)
        _, resistance = file_model(fit.params, data, wire, fit.offsets[k], direction, level, False)
        for d, (colour, label) in BRANCH_STYLE.items():
            rows = np.nonzero(direction == d)[0]
            order = rows[np.argsort(wire[rows])]
            axis.plot(wire[order], data.resistance[order], ".", ms=2, color=colour, alpha=0.4,
                      label=f"data, {label}")
            axis.plot(wire[order], resistance[order], color="k", lw=0.8)
        axis.set(title=f"{data.path.name}: resistance", xlabel="wire temperature [degC]",
                 ylabel="resistance [ohm]")
        axis.grid(alpha=0.3)
        axis.legend(fontsize=7)
    return figure


def isobaric_figures(files, fit, per_cycle=True, rows=()):
    """{file name: PNG bytes} of the fit; ``rows`` are the transformation-table rows."""
    many = max(len(_cycles(d)) for d in files) > GRID_CYCLES
    out = {"fit_isobaric_cycles.png": _png((_overlay if many else _grid)(files, fit, per_cycle)),
           "fit_isobaric_stabilisation.png": _png(_stabilisation(files, list(rows),
                                                                 fit.outlier_cycles or ())),
           "fit_isobaric_residuals.png": _png(_residuals(files, fit))}
    if any(d.resistance is not None for d in files):
        out["fit_isobaric_resistance.png"] = _png(_resistance(files, fit))
    return out
