"""Figures of an isobaric fit (PNG bytes), readable from one to 200 cycles per file.

- ``fit_isobaric_cycles.png``: strain against the *measured* temperature (the
  thermocouple's readings, noise and all), data as points and the model as lines (the model
  against its own temperature axis, so a fitted lag shows as a shift). Up to
  ``GRID_CYCLES`` cycles per file: one panel per cycle in a grid of at most four columns;
  more: one panel per file, every cycle overlaid and coloured by its number. Below each
  file, its own panel of temperature against time or sample: the measured temperature and
  the fitted wire temperature (the profile the model ran on), over at most
  ``TEMPERATURE_CYCLES`` cycles.
- ``fit_isobaric_stabilisation.png``: per-cycle A_s, A_f, M_s, M_f and residual strain
  against cycle number, data (markers) and model (markers joined by lines): the
  stabilisation plot labs use; outlier cycles shaded grey; a residual strain far outside the
  other cycles' is marked at the panel's edge with its value. With one cycle it shows that
  cycle's values, and a quantity no cycle has is said so in its panel.
- ``fit_isobaric_residuals.png``: strain and temperature residuals against sample or time,
  with the noise the verdict judges against (the estimate, or the file's quantisation where larger).
- ``fit_isobaric_resistance.png`` when a file has resistance.

Drawn on :class:`matplotlib.figure.Figure` objects (no pyplot, no backend switch).
"""
import math

import numpy as np
from matplotlib import cm, colormaps, colors
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from sma_fmu.files.png_output import png_bytes
from sma_fmu.identification.figures import BRANCH_STYLE
from sma_fmu.identification.isobaric.jacobian import file_model
from sma_fmu.identification.isobaric.tables import model_branch_strain
from sma_fmu.runtime.constants import HEATING

__all__ = ["isobaric_figures", "GRID_CYCLES", "TEMPERATURE_CYCLES"]

GRID_CYCLES = 12
TEMPERATURE_CYCLES = 4   # cycles shown in a file's temperature panel (the first complete ones)
_MAX_POINTS = 40000   # per file drawn in an overlay (every k-th sample beyond it)


def _png(figure):
    return png_bytes(figure, dpi=90, tight=True)


def _cycles(data):
    cycles = {}
    for index, b in enumerate(data.branches):
        cycles.setdefault(b.cycle, []).append((index, b))
    return cycles


def _model_line(axis, data, fit_file, index, b, colour, lw=1.0, label=None):
    """The model branch over the temperatures its wire branch spans."""
    wire, bounds, params, offsets, per_cycle = fit_file
    of = wire[bounds[index]:bounds[index + 1]]
    if of.size == 0:
        return
    grid = np.linspace(of.min(), of.max(), 300)
    axis.plot(grid, 100 * model_branch_strain(grid, b, data, params, offsets, per_cycle),
              color=colour, lw=lw, label=label, zorder=3)


def _temperature_panel(axis, data, wire, measured_profile, lagged):
    """Measured temperature and the fitted wire temperature against time or sample, over the
    first TEMPERATURE_CYCLES cycles."""
    cycles = sorted({b.cycle for b in data.branches})
    shown = [b for b in data.branches if b.cycle in cycles[:TEMPERATURE_CYCLES]]
    rows = slice(shown[0].start, shown[-1].stop)
    sample = data.time if data.time is not None else np.arange(data.strain.size)
    axis.plot(sample[rows], data.temperature[rows], ".", ms=2, color="0.55",
              label="measured (thermocouple)")
    if lagged:
        axis.plot(sample[rows], measured_profile[rows], "-", lw=0.8, color="tab:orange",
                  label="fitted thermocouple profile")
    axis.plot(sample[rows], wire[rows], "-", lw=1.1, color="k", label="fitted wire temperature")
    which = f"cycles {cycles[0]} to {cycles[min(len(cycles), TEMPERATURE_CYCLES) - 1]}" \
        if len(cycles) > 1 else f"cycle {cycles[0]}"
    axis.set(title=f"{data.path.name}: temperature, {which}" if len(cycles) > 1 else
             f"{data.path.name}: temperature",
             xlabel="time [s]" if data.time is not None else "sample",
             ylabel="temperature [degC]")
    axis.legend(fontsize=7)
    axis.grid(alpha=0.3)


def _cycle_panel(axis, data, fit_file, cycle, branches, legend):
    """One cycle's data against the measured temperature, and the model."""
    for index, b in branches:
        colour, label = BRANCH_STYLE[b.direction]
        of = slice(b.start, b.stop)
        axis.plot(data.temperature[of], 100 * data.strain[of], ".", ms=2, color=colour,
                  alpha=0.4, label=f"data, {label}")
        _model_line(axis, data, fit_file, index, b, "k" if b.direction == HEATING else "0.35",
                    label=f"model, {label}")
    axis.set_title(f"{data.path.name}, cycle {cycle}", fontsize=9)
    axis.set(xlabel="measured temperature [degC]", ylabel="strain [%]")
    axis.grid(alpha=0.3)
    if legend:
        axis.legend(fontsize=6)


def _side_by_side(files, fit, per_cycle):
    """Files of one cycle each: a column per file (four to a row), its cycle above its
    temperature."""
    columns = min(4, len(files))
    rows = math.ceil(len(files) / columns)
    figure = Figure(figsize=(4.2 * columns, 6.2 * rows))
    grid = figure.add_gridspec(2 * rows, columns, height_ratios=[3.4, 2.2] * rows)
    for k, data in enumerate(files):
        row, column = 2 * (k // columns), k % columns
        fit_file = (fit.profiles[k], fit.wire_bounds[k], fit.params, fit.offsets[k], per_cycle)
        (cycle, branches), = _cycles(data).items()
        _cycle_panel(figure.add_subplot(grid[row, column]), data, fit_file, cycle, branches,
                     k == 0)
        _temperature_panel(figure.add_subplot(grid[row + 1, column]), data, fit.profiles[k],
                           fit.measured_profiles[k], fit.lags[k] is not None)
    return figure


def _grid(files, fit, per_cycle):
    counts = [len(_cycles(d)) for d in files]
    if max(counts) == 1:
        return _side_by_side(files, fit, per_cycle)
    columns = min(4, max(counts))
    panel_rows = [math.ceil(c / columns) + 1 for c in counts]   # + the temperature panel
    figure = Figure(figsize=(max(3.8 * columns, 7.0), 3.0 * sum(panel_rows)))
    grid = figure.add_gridspec(sum(panel_rows), columns)
    first_row = 0
    for k, (data, wire, bounds, offsets, rows) in enumerate(
            zip(files, fit.profiles, fit.wire_bounds, fit.offsets, panel_rows)):
        fit_file = (wire, bounds, fit.params, offsets, per_cycle)
        cycles = sorted(_cycles(data).items())
        for j, (cycle, branches) in enumerate(cycles):
            _cycle_panel(figure.add_subplot(grid[first_row + j // columns, j % columns]), data,
                         fit_file, cycle, branches, j == 0)
        _temperature_panel(figure.add_subplot(grid[first_row + rows - 1, :]), data, wire,
                           fit.measured_profiles[k], fit.lags[k] is not None)
        first_row += rows
    return figure


def _overlay(files, fit, per_cycle):
    figure = Figure(figsize=(8.0, 8.4 * len(files)))
    axes = figure.subplots(2 * len(files), 1, squeeze=False,
                           gridspec_kw={"height_ratios": [5.2, 3.0] * len(files)})[:, 0]
    for k, (data, wire, bounds, offsets) in enumerate(zip(files, fit.profiles, fit.wire_bounds,
                                                          fit.offsets)):
        axis = axes[2 * k]
        fit_file = (wire, bounds, fit.params, offsets, per_cycle)
        cycles = sorted(_cycles(data).items())
        numbers = [c for c, _ in cycles]
        norm = colors.Normalize(min(numbers), max(numbers))
        cmap = colormaps["viridis"]
        step = max(1, data.strain.size // _MAX_POINTS)
        cycle_of = np.zeros(data.strain.size)
        for cycle, branches in cycles:
            for _, b in branches:
                cycle_of[b.start:b.stop] = cycle
        axis.scatter(data.temperature[::step], 100 * data.strain[::step], c=cycle_of[::step],
                     cmap="viridis", norm=norm, s=1.5, alpha=0.35, linewidths=0, rasterized=True)
        for cycle, branches in cycles:
            for index, b in branches:
                if b.complete:
                    _model_line(axis, data, fit_file, index, b, cmap(norm(cycle)), lw=0.6)
        bar = figure.colorbar(cm.ScalarMappable(norm=norm, cmap="viridis"), ax=axis)
        bar.set_label("cycle")
        axis.set(title=f"{data.path.name}, {data.load:g} kg: {len(cycles)} cycles\n(points: "
                       f"data against the measured temperature; lines: model)",
                 xlabel="measured temperature [degC]", ylabel="strain [%]")
        axis.grid(alpha=0.3)
        _temperature_panel(axes[2 * k + 1], data, wire, fit.measured_profiles[k],
                           fit.lags[k] is not None)
    return figure


_QUANTITIES = (("A_s", "tab:orange"), ("A_f", "tab:red"), ("M_s", "tab:cyan"), ("M_f", "tab:blue"))


def _no_values(axis, rows, sources):
    """Say in an empty panel why it is empty (the first reason the table gives)."""
    reasons = [r[f"{s}_note"] for r in rows for s in sources if r[f"{s}_note"]]
    text = "no cycle has a value" + (f":\n{reasons[0]}" if reasons else "")
    axis.text(0.5, 0.5, text, ha="center", va="center", transform=axis.transAxes, fontsize=8,
              wrap=True)


BEYOND_SPREADS = 5.0   # a residual strain this many 5-95 % spreads out is marked at the edge


def _stabilisation(files, rows, outliers=()):
    figure = Figure(figsize=(9.0, 7.6 * len(files)))
    axes = figure.subplots(2 * len(files), 1, squeeze=False)[:, 0]
    for k, data in enumerate(files):
        top, bottom = axes[2 * k], axes[2 * k + 1]
        mine = [r for r in rows if r["file"] == data.path.name and r["load_kg"] == data.load]
        numbers = sorted({r["cycle"] for r in mine}) or [1]
        odd = [c["cycle"] for c in outliers if c["file"] == str(data.path)]
        for axis in (top, bottom):
            for n, cycle in enumerate(odd):
                axis.axvspan(cycle - 0.5, cycle + 0.5, color="0.85", zorder=0,
                             label="outlier cycle" if n == 0 else None)
            axis.set_xlim(numbers[0] - 0.6, numbers[-1] + 0.6)
            axis.xaxis.set_major_locator(MaxNLocator(integer=True, min_n_ticks=1))
            axis.grid(alpha=0.3)
        drawn = False
        for quantity, colour in _QUANTITIES:
            these = [r for r in mine if r["quantity"] == quantity]
            cycle = [r["cycle"] for r in these]
            top.plot(cycle, [r["data"] for r in these], "x", ms=4, color=colour, alpha=0.5)
            top.plot(cycle, [r["data_wire"] for r in these], "o", ms=4, color=colour,
                     label=f"{quantity} data")
            top.plot(cycle, [r["model"] for r in these], "-s", lw=1.2, ms=7, color=colour,
                     mfc="none", zorder=3, label=f"{quantity} model")
            drawn = drawn or any(np.isfinite(r[s]) for r in these for s in ("data", "model"))
        if not drawn:
            _no_values(top, [r for r in mine if r["quantity"] in dict(_QUANTITIES)],
                       ("data", "model"))
        top.set_title(f"{data.path.name}: tangent-line temperatures per cycle\n(o: data at the "
                      f"wire temperature, x: at the measured one, squares: model)", fontsize=10)
        top.set(xlabel="cycle", ylabel="temperature [degC]")
        if drawn:
            top.legend(fontsize=7, ncol=5, loc="upper center", bbox_to_anchor=(0.5, -0.16))
        these = [r for r in mine if r["quantity"] == "residual_strain" and r["cycle"] not in odd]
        cycle = [r["cycle"] for r in these]
        bottom.plot(cycle, [r["data_wire"] for r in these], "o", ms=4, color="k",
                    label="data (wire temperature)")
        bottom.plot(cycle, [r["model"] for r in these], "-s", ms=7, mfc="none", zorder=3,
                    color="tab:green", label="model")
        _mark_beyond(bottom, cycle, [r["data_wire"] for r in these] + [r["model"] for r in these])
        if any(np.isfinite(r[s]) for r in these for s in ("data_wire", "model")):
            bottom.legend(fontsize=7)
        else:
            _no_values(bottom, these, ("data_wire", "model"))
        bottom.set(title="residual strain left by each cycle (outlier cycles not drawn; red: beyond "
                         "the axis, at its edge)",
                   xlabel="cycle", ylabel="residual strain [%]")
    return figure


def _mark_beyond(axis, cycles, values):
    """Limit the axis to the bulk of ``values`` (data then model, per cycle) when a few lie
    more than BEYOND_SPREADS times the 5-95 % spread outside it, and mark those at the edge
    with their cycle and value, so one wild cycle neither flattens the others nor
    disappears (a training drift of the first cycles stays on the axis)."""
    v = np.asarray(values, dtype=float)
    finite = v[np.isfinite(v)]
    if finite.size < 4:
        return
    low, high = np.percentile(finite, [5, 95])
    pad = BEYOND_SPREADS * max(high - low, 1e-6)
    low, high = low - pad, high + pad
    cycle = np.tile(np.asarray(cycles), 2)
    beyond = np.isfinite(v) & ((v < low) | (v > high))
    if not beyond.any():
        return
    axis.set_ylim(low, high)
    for n, (c, value) in enumerate(zip(cycle[beyond], v[beyond])):
        edge, marker = (high, "^") if value > high else (low, "v")
        axis.plot([c], [edge], marker, ms=8, color="tab:red", clip_on=False, zorder=4)
        step = 9 * (n % 4) + 10
        axis.annotate(f"cycle {c}: {value:.3g} %", (c, edge), fontsize=7, color="tab:red",
                      xytext=(4, -step if value > high else step - 6), textcoords="offset points")


def _left_out(data, fit, k):
    """Per sample of file ``k``: True where its strain was left out (an outlier cycle)."""
    odd = {c["cycle"] for c in fit.outlier_cycles or () if c["file"] == str(data.path)}
    bounds = fit.wire_bounds[k]
    out = np.zeros(data.strain.size, dtype=bool)
    for index, b in enumerate(data.branches):
        if b.cycle in odd:
            out[bounds[index]:bounds[index + 1]] = True
    return out


def _residuals(files, fit):
    figure = Figure(figsize=(10, 5.2 * len(files)))
    axes = figure.subplots(2 * len(files), 1, squeeze=False)[:, 0]
    floors = fit.floors or [{} for _ in files]
    for k, (data, wire, measured, offsets, sigma, floor) in enumerate(
            zip(files, fit.profiles, fit.measured_profiles, fit.offsets, fit.sigma, floors)):
        sample = data.time if data.time is not None else np.arange(data.strain.size)
        strain, _ = file_model(fit.params, data, wire, offsets, fit.directions[k],
                               fit.row_levels[k], len(offsets) > 1)
        band, label = _band(sigma, floor, "strain")
        _residual_panel(axes[2 * k], sample, 100 * (strain - data.strain), 100 * band,
                        "tab:blue", _left_out(data, fit, k), band_label=label,
                        ylabel="model - data [% strain]",
                        title=f"{data.path.name}: strain residuals (band: the {label})")
        band, label = _band(sigma, floor, "temperature")
        _residual_panel(axes[2 * k + 1], sample, data.temperature - measured, band,
                        "tab:orange", None, band_label=label,
                        xlabel="time [s]" if data.time is not None else "sample",
                        ylabel="measured - fitted [K]",
                        title="thermocouple temperature: measured minus fitted profile")
    return figure


def _band(sigma, floor, key):
    """The residual band of quantity ``key`` and its label: the noise the verdict judges
    against, the estimate or, where larger, the file's quantisation floor."""
    if floor.get(key, 0.0) > sigma[key]:
        return floor[key], "noise floored at the file's resolution"
    return sigma[key], "noise estimate"


def _residual_panel(axis, sample, residual, noise, colour, left_out, band_label, **labels):
    """Residuals against sample or time, with a band of +-``noise`` (named ``band_label``);
    ``left_out`` samples (outlier cycles) in grey, outside the axis range they would set."""
    kept = np.ones(residual.size, dtype=bool) if left_out is None else ~left_out
    axis.plot(sample[kept], residual[kept], ".", ms=1, alpha=0.5, color=colour)
    if not kept.all():
        axis.plot(sample[~kept], residual[~kept], ".", ms=1, alpha=0.3, color="0.6",
                  label="outlier cycles, left out (partly beyond this range)")
        low, high = np.percentile(residual[kept], [0.05, 99.95]) if kept.any() else (-1, 1)
        margin = 0.2 * max(high - low, 2 * noise)
        axis.set_ylim(min(low, -noise) - margin, max(high, noise) + margin)
    axis.axhspan(-noise, noise, color="tab:green", alpha=0.2, label=band_label)
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
            axis.plot(data.temperature[order], data.resistance[order], ".", ms=2, color=colour,
                      alpha=0.4, label=f"data, {label}")
            axis.plot(wire[order], resistance[order], color="k", lw=0.8)
        axis.set(title=f"{data.path.name}: resistance (line: model)",
                 xlabel="measured temperature [degC]", ylabel="resistance [ohm]")
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
