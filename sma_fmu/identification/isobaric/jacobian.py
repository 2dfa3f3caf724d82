"""The isobaric fit's model of one file and its sparse Jacobian.

The model (:func:`sma_fmu.identification.isobaric.terms.branch_curve`) at the wire
temperature T of each sample, on the branch of its direction, plus the strain offset of its
residual-strain level (on cooling, with ``per_cycle``, moving from level k to k + 1 in
proportion to the transformed share q). T = lagged(B c): the profile's knots c and the lag's
time constant, so dT/dc = lagged(B) (sparse: each hat function's decaying response) and
dT/dtau comes from :func:`sma_fmu.identification.isobaric.lag.lag_derivative`.

Derivatives in two steps. A branch (a load, a direction) rests on a dozen numbers, its
:class:`~.terms.BranchScalars` (the stages' centres and energies, w2, the length and
resistance coefficients); the model's derivatives in those and in T, per sample, are in
closed form (:func:`~.terms.curve_derivatives`), and the scalars' derivatives in the
physical unknowns come from central differences of :func:`~.terms.branch_scalars` (cheap:
a dozen numbers per branch, not a file's worth of samples; a new term in the scalars needs
no new derivative code). The offsets enter linearly with weights 1 (heating), 1 - q and q
(cooling). Rows: temperature (profile - measured)/sigma_T, strain, resistance, each times the
sample's weight (0 for a left-out cycle's strain). tests/identification/test_isobaric.py checks it against
central differences of the whole residual.
"""
import numpy as np
from scipy import sparse

from sma_fmu.identification.isobaric.lag import lag_derivative, lagged
from sma_fmu.identification.isobaric.profile import lagged_basis, wire_rows
from sma_fmu.identification.isobaric.terms import (Q_SCALARS, SCALARS, BranchScalars,
                                                   branch_curve, branch_scalars,
                                                   curve_derivatives)
from sma_fmu.identification.measurements import MeasurementError
from sma_fmu.runtime.constants import COOLING, HEATING

__all__ = ["file_state", "file_model", "file_jacobian", "scalar_sensitivities",
           "model_columns", "sparse_rows"]

_RELATIVE = 1e-6      # relative step of the scalars' central differences
_Q = [SCALARS.index(name) for name in Q_SCALARS]
_T_ALPHA = SCALARS.index("T_alpha")
_LENGTHS = [SCALARS.index(name) for name in ("hot0", "hot1", "span0", "span1")]
_RESISTANCES = [SCALARS.index(name) for name in ("resistance_hot", "resistance_span")]


def file_state(x, layout, f):
    """(profile, tau, wire, direction, level, bounds) of file ``f`` at the vector ``x``."""
    profile = f.profile.basis @ x[layout.knots[f.index]]
    tau = x[layout.lags[f.index]] if layout.lags[f.index] is not None else 0.0
    wire = lagged(profile, tau, f.step)
    direction, level, bounds = wire_rows(wire, f.data.branches, f.per_cycle)
    return profile, tau, wire, direction, level, bounds


def _offsets(levels, level, q, cooling, per_cycle):
    """Strain offset [1] of each row and its change per unit q (cooling, per cycle)."""
    offset = levels[np.minimum(level, levels.size - 1)]
    if not (cooling and per_cycle):
        return offset, np.zeros(level.size)
    jump = levels[np.minimum(level + 1, levels.size - 1)] - offset
    return offset + jump * q, jump


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
        strain[rows] = e + _offsets(levels, level[rows], q, d == COOLING, per_cycle)[0]
        resistance[rows] = r
        q_all[rows] = q
    resistance = resistance if data.resistance is not None else None
    return (strain, resistance, q_all) if share else (strain, resistance)


def scalar_sensitivities(x, layout, loads):
    """{(load, direction): (scalars, d scalars / d physical unknowns (scalars x unknowns))}
    at ``x``, by central differences (one-sided at the edge of a parameter's range)."""
    k = len(layout.phys)
    keys = [(load, d) for load in sorted(set(loads)) for d in (HEATING, COOLING)]
    params = layout.params(x)
    base = {key: np.array(branch_scalars(params, *key), dtype=float) for key in keys}
    out = {key: (base[key], np.zeros((len(SCALARS), k))) for key in keys}
    for i in range(k):
        h = 1e-9 if layout.phys[i].startswith("alpha") else _RELATIVE * max(abs(x[i]), 1.0)
        moved, steps = [], []
        for sign in (1.0, -1.0):
            y = np.array(x[:k], dtype=float)
            y[i] += sign * h
            try:
                p = layout.params(y)
            except MeasurementError:      # on the edge of a parameter's range: one-sided
                y[i], p = x[i], params
            steps.append(y[i])
            moved.append(p)
        width = steps[0] - steps[1]
        for key in keys:
            up = np.array(branch_scalars(moved[0], *key), dtype=float)
            down = np.array(branch_scalars(moved[1], *key), dtype=float)
            out[key][1][:, i] = (up - down) / width
    return out


def model_columns(x, layout, f, wire, direction, level, sensitivities):
    """Per sample of file ``f`` at the ``wire`` temperatures: {"strain", "resistance" (or
    None): model values; "strain_phys", "resistance_phys": dense d/d physical unknowns;
    "strain_T", "resistance_T": d/dT [1/K, ohm/K]; "offsets": (rows, columns, values) of
    the strain's offset entries}."""
    n, k = wire.size, len(layout.phys)
    levels = layout.levels(x, f.index)
    with_r = f.data.resistance is not None
    out = {"strain": np.empty(n), "strain_phys": np.zeros((n, k)), "strain_T": np.empty(n),
           "resistance": np.empty(n) if with_r else None,
           "resistance_phys": np.zeros((n, k)) if with_r else None,
           "resistance_T": np.empty(n) if with_r else None}
    first, count, fixed = layout.offsets[f.index]
    off_rows, off_cols, off_values = [], [], []
    for d in (HEATING, COOLING):
        rows = np.nonzero(direction == d)[0]
        if rows.size == 0:
            continue
        scalars, d_scalars = sensitivities[(f.data.load, d)]
        derivative = curve_derivatives(wire[rows], BranchScalars(*scalars),
                                       f.data.reference_length)
        q = derivative["value_q"]
        at = level[rows]
        offset, jump = _offsets(levels, at, q, d == COOLING, f.per_cycle)
        lengths = derivative["strain_lengths"]
        out["strain"][rows] = derivative["strain"] + offset
        per_q = derivative["strain_q"] + jump
        slope = np.zeros((rows.size, len(SCALARS)))
        slope[:, _Q] = per_q[:, None] * derivative["q"]
        slope[:, _T_ALPHA] = -derivative["strain_T"]
        slope[:, _LENGTHS] = lengths
        out["strain_phys"][rows] = slope @ d_scalars
        out["strain_T"][rows] = derivative["strain_T"] + per_q * derivative["dq_dT"]
        if with_r:
            slope = np.zeros((rows.size, len(SCALARS)))
            slope[:, _Q] = derivative["resistance_q"][:, None] * derivative["q"]
            slope[:, _RESISTANCES] = derivative["resistance_levels"]
            out["resistance"][rows] = derivative["resistance"]
            out["resistance_phys"][rows] = slope @ d_scalars
            out["resistance_T"][rows] = derivative["resistance_q"] * derivative["dq_dT"]
        weights = {0: np.ones(rows.size)}
        if d == COOLING and f.per_cycle:
            weights = {0: 1.0 - q, 1: q}
        for shift, weight in weights.items():
            target = np.minimum(at + shift, levels.size - 1) - fixed
            ok = target >= 0
            off_rows.append(rows[ok])
            off_cols.append(first + target[ok])
            off_values.append(weight[ok])
    out["offsets"] = (np.concatenate(off_rows), np.concatenate(off_cols),
                      np.concatenate(off_values))
    return out


def sparse_rows(dense, offsets, extra, n, size):
    """Sparse (n x size) of dense physical columns, offset entries and (rows, cols, values)."""
    rows, cols = np.nonzero(dense)
    parts = [(rows, cols, dense[rows, cols])] + ([offsets] if offsets else []) + extra
    return sparse.csr_matrix((np.concatenate([p[2] for p in parts]),
                              (np.concatenate([p[0] for p in parts]),
                               np.concatenate([p[1] for p in parts]))), shape=(n, size))


def file_jacobian(x, layout, f, sensitivities=None):
    """Sparse Jacobian rows of file ``f``'s residual blocks (temperature, strain, resistance);
    ``sensitivities``: :func:`scalar_sensitivities` at ``x`` (computed when not given)."""
    if sensitivities is None:
        sensitivities = scalar_sensitivities(x, layout, [f.data.load])
    profile, tau, wire, direction, level, _ = file_state(x, layout, f)
    n, size = wire.size, layout.size
    knots = layout.knots[f.index]
    columns = model_columns(x, layout, f, wire, direction, level, sensitivities)
    lag_b = lagged_basis(f.profile, tau, f.step).tocoo()
    temperature = f.profile.basis.tocoo()
    blocks = [sparse.csr_matrix((temperature.data / f.sigma["temperature"],
                                 (temperature.row, knots.start + temperature.col)),
                                shape=(n, size))]
    d_wire_d_tau = lag_derivative(profile, tau, f.step) if layout.lags[f.index] is not None else None
    weight = f.weight
    for key, sigma, offs in (("strain", f.sigma["strain"], columns["offsets"]),
                             ("resistance", f.sigma.get("resistance"), None)):
        dense, slope = columns[f"{key}_phys"], columns[f"{key}_T"]
        if dense is None:
            continue
        extra = [(lag_b.row, knots.start + lag_b.col, slope[lag_b.row] * lag_b.data)]
        if d_wire_d_tau is not None:
            extra.append((np.arange(n), np.full(n, layout.lags[f.index]), slope * d_wire_d_tau))
        blocks.append(sparse.diags(weight / sigma) @ sparse_rows(dense, offs, extra, n, size))
    return blocks
