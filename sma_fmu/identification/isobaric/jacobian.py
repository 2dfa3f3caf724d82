"""The isobaric fit's model of one file and its sparse Jacobian.

The model (:func:`sma_fmu.identification.isobaric.terms.branch_curve`) at the wire
temperature T of each sample, on the branch of its direction, plus the strain offset of its
residual-strain level (on cooling, with ``per_cycle``, moving from level k to k + 1 in
proportion to the transformed share q). T = lagged(B c): the profile's knots c and the lag's
time constant, so dT/dc = lagged(B) (sparse: each hat function's decaying response) and
dT/dtau comes from :func:`sma_fmu.identification.isobaric.lag.lag_derivative`.

Derivatives: d model/d T per sample and d model/d (physical unknown) by central
differences of the vectorised model (the model is smooth, each column costs two model
evaluations of the file, and a new model term needs no new derivative code); the offsets
enter linearly with weights 1 (heating), 1 - q and q (cooling). Rows: temperature
(profile - measured)/sigma_T, strain, resistance, each times the sample's weight (0 for a
left-out cycle's strain). tests/identification/test_isobaric.py checks it against central
differences of the whole residual.
"""
import numpy as np
from scipy import sparse

from sma_fmu.identification.isobaric.lag import lag_derivative, lagged
from sma_fmu.identification.isobaric.profile import lagged_basis, wire_rows
from sma_fmu.identification.isobaric.terms import branch_curve
from sma_fmu.identification.measurements import MeasurementError
from sma_fmu.runtime.constants import COOLING, HEATING

__all__ = ["file_state", "file_model", "file_jacobian", "through_temperature"]

_DT_K = 1e-3          # temperature step of the central difference [K]
_RELATIVE = 1e-6      # relative step of the parameters' central differences


def file_state(x, layout, f):
    """(profile, tau, wire, direction, level, bounds) of file ``f`` at the vector ``x``."""
    profile = f.profile.basis @ x[layout.knots[f.index]]
    tau = x[layout.lags[f.index]] if layout.lags[f.index] is not None else 0.0
    wire = lagged(profile, tau, f.step)
    direction, level, bounds = wire_rows(wire, f.data.branches, f.per_cycle)
    return profile, tau, wire, direction, level, bounds


def file_model(params, data, wire, levels, direction, level, per_cycle=True, share=False):
    """(strain [1], resistance [ohm] or None[, q]) of the model at the ``wire`` temperatures
    [degC], per-row branch ``direction`` and residual-strain ``level``."""
    strain = np.empty(wire.size)
    resistance = np.empty(wire.size)
    q_all = np.empty(wire.size)
    levels = np.asarray(levels, dtype=float)
    for d in (HEATING, COOLING):
        rows = direction == d
        if not rows.any():
            continue
        e, r, q = branch_curve(wire[rows], data.load, d, params, data.reference_length)
        at = level[rows]
        offset = levels[np.minimum(at, levels.size - 1)]
        if d == COOLING and per_cycle:
            offset = offset + (levels[np.minimum(at + 1, levels.size - 1)] - offset) * q
        strain[rows] = e + offset
        resistance[rows] = r
        q_all[rows] = q
    resistance = resistance if data.resistance is not None else None
    return (strain, resistance, q_all) if share else (strain, resistance)


def through_temperature(params, f, wire, levels, direction, level):
    """(d strain/dT [1/K], d resistance/dT [ohm/K] or None) per sample at the wire temperature."""
    up = file_model(params, f.data, wire + _DT_K, levels, direction, level, f.per_cycle)
    down = file_model(params, f.data, wire - _DT_K, levels, direction, level, f.per_cycle)
    d_r = None if up[1] is None else (up[1] - down[1]) / (2 * _DT_K)
    return (up[0] - down[0]) / (2 * _DT_K), d_r


def _parameter_columns(x, layout, f, wire, direction, level):
    """Dense (samples x physical) derivatives of strain and resistance, and the offset entries."""
    k = len(layout.phys)
    n = wire.size
    levels = layout.levels(x, f.index)
    strain = np.zeros((n, k))
    resistance = np.zeros((n, k)) if f.data.resistance is not None else None
    for i in range(k):
        h = 1e-9 if layout.phys[i].startswith("alpha") else _RELATIVE * max(abs(x[i]), 1.0)
        moved, steps = [], []
        for sign in (1.0, -1.0):
            y = x.copy()
            y[i] += sign * h
            try:
                params = layout.params(y)
            except MeasurementError:      # on the edge of a parameter's range: one-sided
                y[i], params = x[i], layout.params(x)
            steps.append(y[i])
            moved.append(file_model(params, f.data, wire, levels, direction, level, f.per_cycle))
        width = steps[0] - steps[1]
        strain[:, i] = (moved[0][0] - moved[1][0]) / width
        if resistance is not None:
            resistance[:, i] = (moved[0][1] - moved[1][1]) / width
    _, _, q = file_model(layout.params(x), f.data, wire, levels, direction, level, f.per_cycle,
                         share=True)
    first, count, fixed = layout.offsets[f.index]
    off_rows, off_cols, off_values = [], [], []
    for d in (HEATING, COOLING):
        rows = np.nonzero(direction == d)[0]
        if rows.size == 0:
            continue
        at = level[rows]
        weights = {0: np.ones(rows.size)}
        if d == COOLING and f.per_cycle:
            weights = {0: 1.0 - q[rows], 1: q[rows]}
        for shift, weight in weights.items():
            target = np.minimum(at + shift, levels.size - 1) - fixed
            ok = target >= 0
            off_rows.append(rows[ok])
            off_cols.append(first + target[ok])
            off_values.append(weight[ok])
    offsets = (np.concatenate(off_rows), np.concatenate(off_cols), np.concatenate(off_values))
    return strain, resistance, offsets


def _block(dense, offsets, extra, n, size):
    """Sparse (n x size) of dense physical columns, offset entries and (rows, cols, values)."""
    rows, cols = np.nonzero(dense)
    parts = [(rows, cols, dense[rows, cols])] + ([offsets] if offsets else []) + extra
    return sparse.csr_matrix((np.concatenate([p[2] for p in parts]),
                              (np.concatenate([p[0] for p in parts]),
                               np.concatenate([p[1] for p in parts]))), shape=(n, size))


def file_jacobian(x, layout, f):
    """Sparse Jacobian rows of file ``f``'s residual blocks (temperature, strain, resistance)."""
    profile, tau, wire, direction, level, _ = file_state(x, layout, f)
    params = layout.params(x)
    levels = layout.levels(x, f.index)
    n, size = wire.size, layout.size
    knots = layout.knots[f.index]
    strain, resistance, offsets = _parameter_columns(x, layout, f, wire, direction, level)
    d_strain, d_resistance = through_temperature(params, f, wire, levels, direction, level)
    lag_b = lagged_basis(f.profile, tau, f.step).tocoo()
    temperature = f.profile.basis.tocoo()
    blocks = [sparse.csr_matrix((temperature.data / f.sigma["temperature"],
                                 (temperature.row, knots.start + temperature.col)),
                                shape=(n, size))]
    d_wire_d_tau = lag_derivative(profile, tau, f.step) if layout.lags[f.index] is not None else None
    weight = f.weight
    for dense, slope, sigma, offs in ((strain, d_strain, f.sigma["strain"], offsets),
                                      (resistance, d_resistance, f.sigma.get("resistance"), None)):
        if dense is None:
            continue
        extra = [(lag_b.row, knots.start + lag_b.col, slope[lag_b.row] * lag_b.data)]
        if d_wire_d_tau is not None:
            extra.append((np.arange(n), np.full(n, layout.lags[f.index]), slope * d_wire_d_tau))
        blocks.append(sparse.diags(weight / sigma) @ _block(dense, offs, extra, n, size))
    return blocks
