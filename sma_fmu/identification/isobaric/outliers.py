"""Outlier cycles and unknowns that end on a bound, for the isobaric fit's report.

An outlier cycle is one whose strain residual RMS (the model at the thermocouple's own
temperature profile, lagged by the fitted lag) exceeds OUTLIER_RATIO times the median
cycle's of its file (a file of fewer than MIN_CYCLES cycles has none: files at several
stresses are not repeats of each other). By default such cycles are left out: their strain rows get
weight 0 and the fit runs again (their temperature rows stay, so the profile stays whole);
``outliers="keep"`` keeps them. A lab's first cycle, unlike the rest, is the usual case.
"""
import numpy as np

__all__ = ["OUTLIER_OPTIONS", "OUTLIER_RATIO", "MIN_CYCLES", "cycle_rms", "mark_outliers",
           "bound_names"]

OUTLIER_OPTIONS = ("leave-out", "keep")
OUTLIER_RATIO = 3.0
MIN_CYCLES = 3


def cycle_rms(prepared, layout, x):
    """[(file index, cycle, strain residual RMS [1], rows)] of every cycle with samples.

    The model runs at the thermocouple's own temperature profile (fitted to the temperature
    alone), lagged by the fitted lag: the fit's joint profile may move a cycle's temperature
    within the thermocouple noise to explain an odd cycle, and would hide it."""
    from sma_fmu.identification.isobaric.jacobian import file_model
    from sma_fmu.identification.isobaric.lag import lagged
    from sma_fmu.identification.isobaric.profile import wire_rows
    params = layout.params(x)
    out = []
    for f in prepared:
        tau = x[layout.lags[f.index]] if layout.lags[f.index] is not None else 0.0
        wire = lagged(f.thermocouple.values, tau, f.step)
        direction, level, bounds = wire_rows(wire, f.data.branches, f.per_cycle)
        strain, _ = file_model(params, f.data, wire, layout.levels(x, f.index), direction, level,
                               f.per_cycle)
        residual = strain - f.data.strain
        cycles = {}
        for index, b in enumerate(f.data.branches):
            cycles.setdefault(b.cycle, []).append(np.arange(bounds[index], bounds[index + 1]))
        for cycle, pieces in sorted(cycles.items()):
            rows = np.concatenate(pieces)
            if rows.size:
                out.append((f.index, cycle, float(np.sqrt(np.mean(residual[rows] ** 2))), rows))
    return out


def mark_outliers(prepared, layout, x, leave_out=True):
    """[{"file", "cycle", "rms", "ratio", "name"}] of the outlier cycles (empty: none), each
    file's cycles against that file's own median (files of fewer than MIN_CYCLES cycles have
    none: a set of files at several stresses is not a set of repeats); with ``leave_out``
    their strain rows get weight 0."""
    cycles = cycle_rms(prepared, layout, x)
    out = []
    for f in prepared:
        out += _outliers(prepared, [c for c in cycles if c[0] == f.index], leave_out)
    return out


def _outliers(prepared, cycles, leave_out):
    if len(cycles) < MIN_CYCLES:
        return []
    median = float(np.median([rms for _, _, rms, _ in cycles]))
    out = []
    for index, cycle, rms, rows in cycles:
        if median > 0 and rms > OUTLIER_RATIO * median:
            if leave_out:
                prepared[index].weight[rows] = 0.0
            name = prepared[index].data.path.name
            out.append({"file": str(prepared[index].data.path), "cycle": cycle, "rms": rms,
                        "ratio": rms / median,
                        "name": f"{name} cycle {cycle} (strain residual RMS {rms:.3g}, "
                                f"{rms / median:.1f}x the median cycle's {median:.3g})"})
    return out


def bound_names(layout, x, lower, upper, relative=1e-6):
    """["name = value (on its lower/upper bound [low, high])"] of the physical unknowns and
    lags that ended on a bound of the box."""
    out = []
    names = list(layout.phys) + [layout.reported[c] for c in layout.lags if c is not None]
    columns = list(range(len(layout.phys))) + [c for c in layout.lags if c is not None]
    for name, c in zip(names, columns):
        low, high = lower[c], upper[c]
        width = high - low if np.isfinite(high - low) else max(abs(x[c]), 1.0)
        for edge, word in ((low, "lower"), (high, "upper")):
            if np.isfinite(edge) and abs(x[c] - edge) <= relative * width:
                out.append(f"{name} = {x[c]:.6g} (on its {word} bound; allowed "
                           f"[{low:.6g}, {high:.6g}])")
    return out
