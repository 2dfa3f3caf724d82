"""Figures like the paper's Figs. 10-11, drawn with matplotlib.

Drawn on :class:`matplotlib.figure.Figure` objects, not through pyplot: no screen is
needed, and importing this module leaves the process's matplotlib backend alone.
"""
from matplotlib.figure import Figure

__all__ = ["plot_run", "plot_comparison"]

_COLOURS = {"pi": "tab:red", "pi+ff-fixed": "tab:orange", "pi+ff-adaptive": "tab:green"}


def plot_run(data, scenario, path):
    """Power and load on top, R_ref and R below (paper Fig. 10); saved as PNG at ``path``."""
    figure = Figure(figsize=(10, 6.5))
    top, bottom = figure.subplots(2, 1, sharex=True)
    t = data["t"]
    top.plot(t[:-1], data["P"][:-1], color="black", lw=0.8, label="P (input power)")
    top.set_ylabel("power P [W]")
    load_axis = top.twinx()
    load_axis.step(t, data["load"], where="post", color="tab:blue", ls="--", label="load")
    load_axis.set_ylabel("load [kg]", color="tab:blue")
    load_axis.set_ylim(0, max(0.3, 1.1 * float(data["load"].max())))
    bottom.plot(t, data["R_ref"], color="black", ls="--", lw=0.9, label="R_ref")
    bottom.plot(t, data["R"], color="tab:red", lw=0.9, label="R")
    bottom.set_xlabel("time t [s]")
    bottom.set_ylabel("resistance [ohm]")
    bottom.legend(loc="upper right")
    top.set_title(f"{scenario.name}: {scenario.controller.kind}, {scenario.hysteresis_mode} hysteresis")
    for axis in (top, bottom):
        axis.grid(alpha=0.3)
    figure.tight_layout()
    figure.savefig(path, dpi=110)


def plot_comparison(runs, title, path, zoom=(24.0, 28.0)):
    """Overlay controllers: R over the run, a zoomed window (paper Fig. 11) and the error.

    ``runs`` maps controller kind -> time-series array of the same scenario group.
    """
    figure = Figure(figsize=(10, 9))
    axes = figure.subplots(3, 1)
    first = next(iter(runs.values()))
    t = first["t"]
    zoomed = (t >= zoom[0]) & (t <= zoom[1])
    for axis, mask in ((axes[0], slice(None)), (axes[1], zoomed)):
        axis.plot(t[mask], first["R_ref"][mask], color="black", ls="--", lw=1.0, label="R_ref")
    for kind, data in runs.items():
        colour = _COLOURS.get(kind)
        axes[0].plot(t, data["R"], color=colour, lw=0.8, label=kind)
        axes[1].plot(t[zoomed], data["R"][zoomed], color=colour, lw=1.2, label=kind)
        axes[2].plot(t, data["R"] - data["R_ref"], color=colour, lw=0.8, label=kind)
    axes[0].set_title(title)
    axes[0].set_ylabel("resistance [ohm]")
    axes[1].set_ylabel("resistance [ohm]")
    axes[1].set_title(f"enlarged: {zoom[0]:g} s to {zoom[1]:g} s")
    axes[2].set_ylabel("error R - R_ref [ohm]")
    axes[2].set_xlabel("time t [s]")
    for axis in axes:
        axis.grid(alpha=0.3)
        axis.legend(loc="upper right", fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
