"""Figures of runs: one per scenario (like the paper's Fig. 10) and one per comparison (Fig. 11).

Drawn on :class:`matplotlib.figure.Figure` objects, not through pyplot: no screen is
needed, and importing this module leaves the process's matplotlib backend alone. Every
panel has a legend; the load changes and the start of the metrics window are marked on
every panel that shows the whole run.

**Choice: each line is drawn through its envelope** (:func:`envelope`): a 30-s run has
30,001 samples a line, some 40 times the pixels a panel is wide, and matplotlib spent most
of a figure's time on them. Cut into 1,500 spans, each span's lowest and highest sample in
their order keeps every peak a pixel column shows, so the figure looks the same and takes
a quarter of the time. **No layout pass** (``tight_layout`` draws the whole figure once
to measure it, a third of a comparison's time): the run figure's margins are fixed (the
values ``tight_layout`` found for every shipped scenario: its labels and legends are the
same text for each run); the comparison's are too, but for its right margin, which makes
room for the widest of its outside legends (they hold the runs' names), measured alone
(:func:`_legend_margin`). **The run figure is made once** (for runs with the
feedforward's lines and without: a run without them leaves those lines empty and out of
the legends) and drawn again for each run with its data: making the axes and their ticks
was half of its time, a second kind's first drawing (its ticks made, its texts measured)
a third more than its later ones, and a kept figure draws the same PNG bytes as a new
one. The comparison's axes are kept too, emptied of the last comparison's artists.
Each thread keeps figures of its own. **A kept figure keeps its Agg canvas, at the PNG's
dpi**: savefig otherwise makes a new canvas and renderer for each PNG, and matplotlib's
cache of text sizes is per renderer, so every figure measured its texts again (the same
tick labels and legend entries each run): 15 % of a figure's time.
"""
import threading

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from sma_fmu.runtime.signals import is_stroke

__all__ = ["plot_run", "plot_comparison", "rolling_rms", "envelope", "ENVELOPE_SPANS"]

ENVELOPE_SPANS = 1500   # spans a line is cut into: more than the pixels a panel is wide
# the run figure's margins (as fractions of the figure): what tight_layout gave for all the
# shipped scenarios, the left one a little wider (0.076-0.079 there)
_RUN_MARGINS = {"left": 0.08, "right": 0.782, "top": 0.964, "bottom": 0.059, "hspace": 0.121}
# the comparison's margins: tight_layout's for the paper's groups; its right margin at most
_COMPARISON_MARGINS = {"left": 0.063, "right": 0.817, "top": 0.964, "bottom": 0.059,
                       "wspace": 0.18, "hspace": 0.321}
_LEGEND_PAD = 1.08   # [font sizes] beside an outside legend, tight_layout's pad
_DPI = 110           # [dots per inch] the PNGs' resolution: 1100 px a 10-inch figure
# zlib level 1 instead of Pillow's 6: a figure's PNG 35 % faster to write, 5 % larger
_PNG = {"compress_level": 1}

_FEEDFORWARD_LINES = ("T_ref", "P_ff")   # the run figure's lines of the feedforward only
_COLOURS = {"pi": "tab:red", "pi+ff-fixed": "tab:orange", "pi+ff-adaptive": "tab:green"}
_EXTRA_COLOURS = ("tab:blue", "tab:purple", "tab:brown", "tab:pink", "tab:olive", "tab:cyan")


def _colours(labels):
    """A colour per run label: the paper's three controllers keep theirs."""
    extra = iter(_EXTRA_COLOURS * (1 + len(labels) // len(_EXTRA_COLOURS)))
    return {label: _COLOURS.get(label) or next(extra) for label in labels}


def envelope(x, y, spans=ENVELOPE_SPANS):
    """(x, y) to draw for the line ``y`` over ``x``: unchanged up to 4 ``spans`` samples;
    longer, cut into ``spans`` spans of equal count (the rest a span of its own), each
    giving its lowest and highest sample, in their order. NaN samples lose to any number
    (a span of NaN alone stays NaN: a gap)."""
    x, y = np.asarray(x), np.asarray(y)
    if len(y) <= 4 * spans:
        return x, y
    width = len(y) // spans
    whole = width * spans
    xs, ys = x[:whole].reshape(spans, width), y[:whole].reshape(spans, width)
    missing = np.isnan(ys)
    low = np.where(missing, np.inf, ys).argmin(axis=1)
    high = np.where(missing, -np.inf, ys).argmax(axis=1)
    order = np.stack([np.minimum(low, high), np.maximum(low, high)], axis=1)
    rows = np.arange(spans)[:, None]
    return (np.concatenate([xs[rows, order].ravel(), x[whole:]]),
            np.concatenate([ys[rows, order].ravel(), y[whole:]]))


def _agg_figure(figsize):
    """A :class:`Figure` of ``figsize`` [inches] at the PNGs' dpi, on an Agg canvas of its
    own: savefig draws on that canvas and keeps its renderer, and with it matplotlib's
    cache of text sizes, from one PNG to the next."""
    figure = Figure(figsize=figsize, dpi=_DPI)
    FigureCanvasAgg(figure)
    return figure


def _agg_canvas(figure):
    """``figure``'s Agg canvas (one made for it if it has none)."""
    canvas = figure.canvas
    return canvas if isinstance(canvas, FigureCanvasAgg) else FigureCanvasAgg(figure)


def _line(axis, x, y, **style):
    """``axis.plot`` of the :func:`envelope` of ``y`` over ``x``."""
    return axis.plot(*envelope(x, y), **style)


def _title(axis, text):
    """``axis.set_title`` at the top edge: no axis here has tick labels above it, where
    matplotlib would move a title to, and looking for them cost a sixth of a figure's drawing."""
    axis.set_title(text, y=1.0)


def _load_changes(data):
    """[(time [s], new load [kg])] where the load steps."""
    load = data["load"]
    steps = np.nonzero(np.diff(load) != 0.0)[0] + 1
    return [(float(data["t"][i]), float(load[i])) for i in steps]


def _mark(axis, data, metrics_start, label=False):
    """Grey out the samples before the metrics window and draw a line at each load change;
    returns the artists (a reused figure removes them before the next run)."""
    marks = []
    if metrics_start > 0.0:
        marks.append(axis.axvspan(data["t"][0], metrics_start, color="0.85", alpha=0.6, lw=0,
                                  label="outside the metrics window" if label else None))
    for index, (time, load) in enumerate(_load_changes(data)):
        marks.append(axis.axvline(time, color="0.35", ls=":", lw=1.0,
                                  label="load change" if label and index == 0 else None))
        if label:
            marks.append(axis.annotate(f"{load:g} kg", (time, 1.0), xycoords=("data", "axes fraction"),
                                       xytext=(3, -12), textcoords="offset points", fontsize=8,
                                       color="0.3"))
    return marks


class _RunFigure:
    """The run figure's axes and lines, made once and drawn again for each run with its
    data (:func:`plot_run`): making the axes and their ticks was half of a figure's time.
    One per kind (with or without a stroke reference's curve, its panel taller); a run
    without a feedforward leaves its lines (T_ref, P_ff) empty and out of the legends."""

    def __init__(self, stroke_reference=False):
        self.figure = _agg_figure(figsize=(10, 10))
        self.axes = self.figure.subplots(4, 1, sharex=True, gridspec_kw={
            "height_ratios": [3, 2, 2, 2.6 if stroke_reference else 1.4]})
        resistance, temperature, power, load = self.axes
        self.stroke = load.twinx()
        thin = {"lw": 0.9}
        self.lines = {   # column -> (axis, its line; whether it ends one row early: no step there)
            "R_ref": (resistance, dict(color="black", ls="--", label="R_ref", **thin), False),
            "R": (resistance, dict(color="tab:red", label="R", **thin), False),
            "T": (temperature, dict(color="tab:red", label="T (wire)", **thin), False),
            "T_ref": (temperature, dict(color="black", ls="--", label="T_ref (inverse model)",
                                        **thin), False),
            "P": (power, dict(color="black", label="P applied", **thin), True),
            "P_ff": (power, dict(color="tab:blue", lw=0.8, label="P_ff (feedforward)"), True),
            "P_fb": (power, dict(color="tab:orange", lw=0.8, label="P_fb (PI feedback)"), True),
            "stroke_reference": (self.stroke, dict(color="black", ls="--", label="stroke reference",
                                                   **thin), False),
            "stroke": (self.stroke, dict(color="tab:green", label="stroke x_0 - x", **thin), False)}
        if not stroke_reference:
            del self.lines["stroke_reference"]
        self.lines = {name: (axis.plot([], [], **style)[0], early)
                      for name, (axis, style, early) in self.lines.items()}
        self.room = temperature.axhline(0.0, color="tab:blue", lw=0.8, ls="-.", label="T_room")
        power.axhline(0.0, color="0.5", lw=0.6)
        self.load = load.step([], [], where="post", color="tab:blue", label="load")[0]
        for axis, label in zip((*self.axes, self.stroke), ("resistance [ohm]", "temperature [degC]",
                                                          "power [W]", "load [kg]", "stroke [mm]")):
            axis.set_ylabel(label)
        load.set_xlabel("time t [s]")
        for axis in self.axes:
            axis.grid(alpha=0.3)
        self.figure.subplots_adjust(**_RUN_MARGINS)
        self.marks = []

    def draw(self, data, scenario, path):
        """Draw the run ``data`` of ``scenario`` and write the PNG at ``path``."""
        resistance, temperature, power, load = self.axes
        t = data["t"]
        feedforward = bool(scenario.controller.feedforward)
        for name, (line, early) in self.lines.items():
            if name in _FEEDFORWARD_LINES:   # without a feedforward: empty, out of legends ("_")
                label = line.get_label().lstrip("_")
                line.set_label(label if feedforward else f"_{label}")
                if not feedforward:
                    line.set_data([], [])
                    continue
            if name == "stroke_reference":
                values = 1e3 * np.array(scenario.reference.strokes(t.tolist()))
            else:
                values = 1e3 * data["stroke"] if name == "stroke" else data[name]
            line.set_data(*envelope(t[:-1], values[:-1]) if early else envelope(t, values))
        self.room.set_ydata([scenario.params.T_room] * 2)
        changes = np.concatenate([[0], np.nonzero(np.diff(data["load"]) != 0.0)[0] + 1, [len(t) - 1]])
        self.load.set_data(t[changes], data["load"][changes])
        load.set_ylim(0.0, max(0.3, 1.15 * float(data["load"].max())))
        for mark in self.marks:
            mark.remove()
        self.marks = [mark for index, axis in enumerate(self.axes)
                      for mark in _mark(axis, data, scenario.analysis.metrics_start_s, index == 0)]
        for axis in (*self.axes, self.stroke):
            axis.relim()
        for axis in (*self.axes, self.stroke):
            axis.autoscale_view()
        for axis in (resistance, temperature, power):
            axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, borderaxespad=0)
        handles = load.get_legend_handles_labels()[0] + self.stroke.get_legend_handles_labels()[0]
        load.legend(handles, [h.get_label() for h in handles], loc="upper left",
                    bbox_to_anchor=(1.08, 1.0), fontsize=8, borderaxespad=0)
        _title(resistance, f"{scenario.name}: {scenario.controller.kind}, "
                           f"{scenario.hysteresis_mode} hysteresis")
        self.figure.savefig(path, dpi=_DPI, pil_kwargs=_PNG)


_KEPT = threading.local()   # each thread's kept figures: one figure is never drawn by two at once


def _kept(name, make):
    """This thread's kept figure ``name``, made by ``make()`` at its first use."""
    value = getattr(_KEPT, name, None)
    if value is None:
        value = make()
        setattr(_KEPT, name, value)
    return value


def plot_run(data, scenario, path):
    """Resistance, temperature, power (total, feedforward, feedback), load and stroke (with a
    stroke reference's curve, its panel taller); PNG at ``path``. The figure is kept for the
    next run of the same kind (:class:`_RunFigure`)."""
    stroke_reference = is_stroke(scenario.reference)
    _kept("run" + ("_stroke" if stroke_reference else ""),
          lambda: _RunFigure(stroke_reference)).draw(data, scenario, path)


def rolling_rms(values, window):
    """Root mean square of ``values`` over a centred window of ``window`` samples (same length)."""
    window = max(1, min(int(window), len(values)))
    squares = np.concatenate([[0.0], np.cumsum(np.square(values))])
    half = window // 2
    index = np.arange(len(values))
    low = np.clip(index - half, 0, len(values))
    high = np.clip(index - half + window, 0, len(values))
    return np.sqrt((squares[high] - squares[low]) / np.maximum(high - low, 1))


def _reference_period(scenario):
    """Period of a periodic reference [s], or a twentieth of the run for the others."""
    settings = scenario.reference.settings
    frequency = settings.get("frequency_hz", 0.0) if scenario.reference.kind in ("sine", "cosine") else 0.0
    return 1.0 / frequency if frequency > 0.0 else scenario.stop_time_s / 20.0


def _legend_margin(figure, legends, left, widest):
    """The right margin (a fraction of the figure) that leaves room for ``legends``, placed
    just outside their axes' right edge (``bbox_to_anchor`` (1.01, 1)): ``widest`` at most.
    Measures the legends alone, not the figure."""
    renderer = _agg_canvas(figure).get_renderer()   # the canvas savefig draws PNGs on
    width = figure.bbox.width
    room = max(legend.get_window_extent(renderer).width for legend in legends)
    pad = _LEGEND_PAD * legends[0].prop.get_size_in_points() * figure.dpi / 72.0
    # the legend starts at right + 0.01 * (right - left), ends ``room`` + ``pad`` later
    return min(widest, (1.0 - (room + pad) / width + 0.01 * left) / 1.01)


def _new_comparison_axes():
    """(figure, its four axes: overview, zoomed, zoomed error, RMS) for a comparison."""
    figure = _agg_figure(figsize=(12, 10))
    grid = figure.add_gridspec(3, 2, height_ratios=[1.1, 1.2, 1.0])
    overview = figure.add_subplot(grid[0, :])
    zoomed = figure.add_subplot(grid[1, 0])
    zoomed_error = figure.add_subplot(grid[1, 1], sharex=zoomed)
    rms = figure.add_subplot(grid[2, :], sharex=overview)
    for axis in (overview, zoomed, zoomed_error, rms):
        axis.grid(alpha=0.3)
    return figure, (overview, zoomed, zoomed_error, rms)


def _comparison_axes():
    """(figure, its four axes) for a comparison: made once, then kept with their ticks and
    emptied of the last comparison's lines, spans, texts and legends (making the axes and
    their ticks was half of a comparison's time; the test compares its PNG with a new
    figure's, byte for byte)."""
    figure, axes = _kept("comparison", _new_comparison_axes)
    for axis in axes:
        for artist in [*axis.lines, *axis.patches, *axis.texts]:
            artist.remove()
        if axis.get_legend() is not None:
            axis.get_legend().remove()
    return figure, axes


def plot_comparison(runs, scenario, title, path):
    """Overlay runs of one group: the whole run, an enlarged window, and the error.

    ``runs`` maps a label (controller kind or scenario name) to the time series of runs of
    one group; ``scenario`` (any of them) gives the windows and the reference period. Panels:
    R over the whole run; R and the error R - R_ref in the enlarged window (the paper's
    Fig. 11); the RMS error over one reference period, over the whole run.
    """
    labels = list(runs)
    colours = _colours(labels)
    first = runs[labels[0]]
    t = first["t"]
    window = scenario.analysis
    zoom = (t >= window.zoom_start_s) & (t <= window.zoom_end_s)
    figure, (overview, zoomed, zoomed_error, rms) = _comparison_axes()
    _line(overview, t, first["R_ref"], color="black", ls="--", lw=0.8, label="R_ref")
    _line(zoomed, t[zoom], first["R_ref"][zoom], color="black", ls="--", lw=1.1, label="R_ref")
    # the series may hold every k-th step (an output interval, a long run's figure rows)
    spacing = float(np.median(np.diff(t))) if len(t) > 1 else scenario.step_s
    samples = max(1, int(round(_reference_period(scenario) / spacing)))
    for label, data in runs.items():
        colour, error = colours[label], data["R"] - data["R_ref"]
        _line(overview, t, data["R"], color=colour, lw=0.6, label=label)
        _line(zoomed, t[zoom], data["R"][zoom], color=colour, lw=1.2, label=label)
        _line(zoomed_error, t[zoom], error[zoom], color=colour, lw=1.2, label=label)
        _line(rms, t, rolling_rms(error, samples), color=colour, lw=1.2, label=label)
    overview.set(ylabel="resistance [ohm]")
    _title(overview, f"{title}: whole run")
    zoomed.set(ylabel="resistance [ohm]", xlabel="time t [s]")
    _title(zoomed, f"enlarged: {window.zoom_start_s:g} s to {window.zoom_end_s:g} s")
    zoomed_error.set(ylabel="error R - R_ref [ohm]", xlabel="time t [s]")
    _title(zoomed_error, "error, enlarged")
    zoomed_error.axhline(0.0, color="0.5", lw=0.6)
    rms.set(ylabel="RMS error [ohm]", xlabel="time t [s]")
    _title(rms, f"RMS of R - R_ref over {samples * spacing:g} s (one reference period)")
    for index, axis in enumerate((overview, rms)):
        _mark(axis, first, window.metrics_start_s, label=index == 0)
    overview.axvspan(window.zoom_start_s, window.zoom_end_s, color="tab:blue", alpha=0.08, lw=0,
                     label="enlarged below")
    outside = [axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8,
                           borderaxespad=0) for axis in (overview, rms)]
    for axis in (zoomed, zoomed_error):
        axis.legend(loc="best", fontsize=7, framealpha=0.7)
    for axis in (overview, zoomed, zoomed_error, rms):
        axis.relim()   # the kept axes' data limits: those of this figure's artists only
    for axis in (overview, zoomed, zoomed_error, rms):
        axis.autoscale_view()
    margins = dict(_COMPARISON_MARGINS)
    margins["right"] = _legend_margin(figure, outside, margins["left"], margins["right"])
    figure.subplots_adjust(**margins)
    figure.savefig(path, dpi=_DPI, pil_kwargs=_PNG)
