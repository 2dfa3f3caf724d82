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
(:func:`_legend_margin`).
"""
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

__all__ = ["plot_run", "plot_comparison", "rolling_rms", "envelope", "ENVELOPE_SPANS"]

ENVELOPE_SPANS = 1500   # spans a line is cut into: more than the pixels a panel is wide
# the run figure's margins (as fractions of the figure): what tight_layout gave for all the
# shipped scenarios, the left one a little wider (0.076-0.079 there)
_RUN_MARGINS = {"left": 0.08, "right": 0.782, "top": 0.964, "bottom": 0.059, "hspace": 0.121}
# the comparison's margins: tight_layout's for the paper's groups; its right margin at most
_COMPARISON_MARGINS = {"left": 0.063, "right": 0.817, "top": 0.964, "bottom": 0.059,
                       "wspace": 0.18, "hspace": 0.321}
_LEGEND_PAD = 1.08   # [font sizes] beside an outside legend, tight_layout's pad
# zlib level 1 instead of Pillow's 6: a figure's PNG 35 % faster to write, 5 % larger
_PNG = {"compress_level": 1}

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


def _line(axis, x, y, **style):
    """``axis.plot`` of the :func:`envelope` of ``y`` over ``x``."""
    return axis.plot(*envelope(x, y), **style)


def _load_changes(data):
    """[(time [s], new load [kg])] where the load steps."""
    load = data["load"]
    steps = np.nonzero(np.diff(load) != 0.0)[0] + 1
    return [(float(data["t"][i]), float(load[i])) for i in steps]


def _mark(axis, data, metrics_start, label=False):
    """Grey out the samples before the metrics window and draw a line at each load change."""
    if metrics_start > 0.0:
        axis.axvspan(data["t"][0], metrics_start, color="0.85", alpha=0.6, lw=0,
                     label="outside the metrics window" if label else None)
    for index, (time, load) in enumerate(_load_changes(data)):
        axis.axvline(time, color="0.35", ls=":", lw=1.0,
                     label="load change" if label and index == 0 else None)
        if label:
            axis.annotate(f"{load:g} kg", (time, 1.0), xycoords=("data", "axes fraction"),
                          xytext=(3, -12), textcoords="offset points", fontsize=8, color="0.3")


def plot_run(data, scenario, path):
    """Resistance, temperature, power (total, feedforward, feedback), load and stroke; PNG at ``path``."""
    figure = Figure(figsize=(10, 10))
    axes = figure.subplots(4, 1, sharex=True, gridspec_kw={"height_ratios": [3, 2, 2, 1.4]})
    t = data["t"]
    start = scenario.analysis.metrics_start_s
    resistance, temperature, power, load = axes
    _line(resistance, t, data["R_ref"], color="black", ls="--", lw=0.9, label="R_ref")
    _line(resistance, t, data["R"], color="tab:red", lw=0.9, label="R")
    resistance.set_ylabel("resistance [ohm]")
    _line(temperature, t, data["T"], color="tab:red", lw=0.9, label="T (wire)")
    if scenario.controller.feedforward:
        _line(temperature, t, data["T_ref"], color="black", ls="--", lw=0.9,
              label="T_ref (inverse model)")
    temperature.axhline(scenario.params.T_room, color="tab:blue", lw=0.8, ls="-.", label="T_room")
    temperature.set_ylabel("temperature [degC]")
    _line(power, t[:-1], data["P"][:-1], color="black", lw=0.9, label="P applied")
    if scenario.controller.feedforward:
        _line(power, t[:-1], data["P_ff"][:-1], color="tab:blue", lw=0.8, label="P_ff (feedforward)")
    _line(power, t[:-1], data["P_fb"][:-1], color="tab:orange", lw=0.8, label="P_fb (PI feedback)")
    power.axhline(0.0, color="0.5", lw=0.6)
    power.set_ylabel("power [W]")
    changes = np.concatenate([[0], np.nonzero(np.diff(data["load"]) != 0.0)[0] + 1, [len(t) - 1]])
    load.step(t[changes], data["load"][changes], where="post", color="tab:blue", label="load")
    load.set_ylabel("load [kg]")
    load.set_ylim(0.0, max(0.3, 1.15 * float(data["load"].max())))
    stroke = load.twinx()
    _line(stroke, t, 1e3 * data["stroke"], color="tab:green", lw=0.9, label="stroke x_0 - x")
    stroke.set_ylabel("stroke [mm]")
    load.set_xlabel("time t [s]")
    for index, axis in enumerate(axes):
        _mark(axis, data, start, label=index == 0)
        axis.grid(alpha=0.3)
    for axis in (resistance, temperature, power):
        axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, borderaxespad=0)
    handles = load.get_legend_handles_labels()[0] + stroke.get_legend_handles_labels()[0]
    load.legend(handles, [h.get_label() for h in handles], loc="upper left",
                bbox_to_anchor=(1.08, 1.0), fontsize=8, borderaxespad=0)
    resistance.set_title(f"{scenario.name}: {scenario.controller.kind}, "
                         f"{scenario.hysteresis_mode} hysteresis")
    figure.subplots_adjust(**_RUN_MARGINS)
    figure.savefig(path, dpi=110, pil_kwargs=_PNG)


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
    renderer = FigureCanvasAgg(figure).get_renderer()   # the canvas savefig draws PNGs on
    width = figure.bbox.width
    room = max(legend.get_window_extent(renderer).width for legend in legends)
    pad = _LEGEND_PAD * legends[0].prop.get_size_in_points() * figure.dpi / 72.0
    # the legend starts at right + 0.01 * (right - left), ends ``room`` + ``pad`` later
    return min(widest, (1.0 - (room + pad) / width + 0.01 * left) / 1.01)


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
    figure = Figure(figsize=(12, 10))
    grid = figure.add_gridspec(3, 2, height_ratios=[1.1, 1.2, 1.0])
    overview = figure.add_subplot(grid[0, :])
    zoomed = figure.add_subplot(grid[1, 0])
    zoomed_error = figure.add_subplot(grid[1, 1], sharex=zoomed)
    rms = figure.add_subplot(grid[2, :], sharex=overview)
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
    overview.set(ylabel="resistance [ohm]", title=f"{title}: whole run")
    zoomed.set(ylabel="resistance [ohm]", xlabel="time t [s]",
               title=f"enlarged: {window.zoom_start_s:g} s to {window.zoom_end_s:g} s")
    zoomed_error.set(ylabel="error R - R_ref [ohm]", xlabel="time t [s]", title="error, enlarged")
    zoomed_error.axhline(0.0, color="0.5", lw=0.6)
    rms.set(ylabel="RMS error [ohm]", xlabel="time t [s]",
            title=f"RMS of R - R_ref over {samples * spacing:g} s (one reference period)")
    for index, axis in enumerate((overview, rms)):
        _mark(axis, first, window.metrics_start_s, label=index == 0)
    overview.axvspan(window.zoom_start_s, window.zoom_end_s, color="tab:blue", alpha=0.08, lw=0,
                     label="enlarged below")
    outside = [axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8,
                           borderaxespad=0) for axis in (overview, rms)]
    for axis in (zoomed, zoomed_error):
        axis.legend(loc="best", fontsize=7, framealpha=0.7)
    for axis in (overview, zoomed, zoomed_error, rms):
        axis.grid(alpha=0.3)
    margins = dict(_COMPARISON_MARGINS)
    margins["right"] = _legend_margin(figure, outside, margins["left"], margins["right"])
    figure.subplots_adjust(**margins)
    figure.savefig(path, dpi=110, pil_kwargs=_PNG)
