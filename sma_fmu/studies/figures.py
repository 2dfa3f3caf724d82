"""Figures of a sweep, on :class:`matplotlib.figure.Figure` objects (never pyplot).

Each function takes the rows of one base scenario (a DataFrame of the results table,
successful runs only) and returns a Figure; the caller saves it.
"""
import numpy as np
from matplotlib.figure import Figure

from sma_fmu.files.png_output import tight_layout

__all__ = ["heat_map_figure", "line_figure", "distribution_figure"]


def heat_map_figure(rows, x_key, y_key, title):
    """Mean RMSE [ohm] over a 2-D grid of ``x_key`` x ``y_key`` (other inputs averaged)."""
    grid = rows.pivot_table(index=y_key, columns=x_key, values="rmse_ohm", aggfunc="mean")
    figure = Figure(figsize=(7.5, 5.5))
    axis = figure.subplots()
    image = axis.imshow(grid.to_numpy(dtype=float), origin="lower", aspect="auto", cmap="viridis")
    axis.set_xticks(range(grid.shape[1]), [f"{v:.3g}" for v in grid.columns], rotation=45)
    axis.set_yticks(range(grid.shape[0]), [f"{v:.3g}" for v in grid.index])
    axis.set_xlabel(x_key)
    axis.set_ylabel(y_key)
    values = grid.to_numpy(dtype=float)
    best = np.unravel_index(np.nanargmin(values), values.shape)
    for (i, j), value in np.ndenumerate(values):
        axis.text(j, i, f"{value:.2f}", ha="center", va="center", fontsize=7,
                  color="white" if (i, j) != best else "red")
    figure.colorbar(image, ax=axis, label="RMSE of R - R_ref [ohm]")
    axis.set_title(f"{title}: RMSE (best in red)")
    tight_layout(figure)
    return figure


def line_figure(rows, key, title):
    """RMSE [ohm] against one axis (mean and range over the other inputs)."""
    grouped = rows.groupby(key)["rmse_ohm"]
    mean, low, high = grouped.mean(), grouped.min(), grouped.max()
    figure = Figure(figsize=(7, 4.5))
    axis = figure.subplots()
    axis.plot(mean.index, mean.to_numpy(), "o-", color="tab:blue", label="mean")
    axis.fill_between(mean.index, low.to_numpy(), high.to_numpy(), alpha=0.25, color="tab:blue",
                      label="min ... max")
    axis.set(xlabel=key, ylabel="RMSE of R - R_ref [ohm]", title=title)
    axis.grid(alpha=0.3)
    axis.legend()
    tight_layout(figure)
    return figure


def distribution_figure(rows, wire_keys, title):
    """Monte Carlo: histogram of the RMSE [ohm], and RMSE against the most correlated parameter."""
    rmse = rows["rmse_ohm"].to_numpy(dtype=float)
    figure = Figure(figsize=(11, 4.5))
    left, right = figure.subplots(1, 2)
    left.hist(rmse, bins=max(10, min(60, int(np.sqrt(rmse.size)))), color="tab:blue", alpha=0.8)
    for value, style, label in ((np.median(rmse), "-", "median"),
                                (np.percentile(rmse, 5), "--", "5 %"),
                                (np.percentile(rmse, 95), "--", "95 %")):
        left.axvline(value, color="black", ls=style, lw=1, label=f"{label} {value:.3f} ohm")
    left.set(xlabel="RMSE of R - R_ref [ohm]", ylabel="runs",
             title=f"{title}: {rmse.size} runs")
    left.legend(fontsize=8)
    correlations = {key: _correlation(rows[key].to_numpy(dtype=float), rmse) for key in wire_keys}
    if correlations:
        key = max(correlations, key=lambda k: abs(correlations[k]))
        right.plot(rows[key].to_numpy(dtype=float), rmse, ".", ms=3, alpha=0.5)
        right.set(xlabel=key, ylabel="RMSE [ohm]",
                  title=f"strongest link: {key} (r = {correlations[key]:+.2f})")
    for axis in (left, right):
        axis.grid(alpha=0.3)
    tight_layout(figure)
    return figure


def _correlation(x, y):
    if x.size < 3 or np.std(x) == 0.0 or np.std(y) == 0.0:
        return 0.0
    return float(np.corrcoef(x, y)[0, 1])
