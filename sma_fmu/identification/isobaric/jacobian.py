"""The isobaric fit's model of one file and its sparse closed-form Jacobian.

With q = 1/(1 + e^Lambda), Lambda = E (1/tau_K - 1/T_K), E = nu (eps_T - g f x_T/N)/k_B and
x_T = x_min - l_MF, the strain residual eps_hot + (span + d_offset) q + offset - data
differentiates through q (dq/dLambda = -q(1-q)) into the centres (a, b), E (nu, l_MF,
x_min) and the wire temperature T; T = lagged(B c) (the profile's knots c, the lag's time
constant), so dT/dc = lagged(B) (sparse: each hat function's decaying response) and dT/dtau
comes from :func:`sma_fmu.identification.isobaric.lag.lag_derivative`. The levels
(l_MF, x_min, R_P, R_MF) and the offsets enter directly. Rows: temperature (profile -
measured)/sigma_T, strain, resistance. tests/test_isobaric.py checks it against central
differences.
"""
import numpy as np
from scipy import sparse

from sma_fmu.identification.isobaric.lag import lag_derivative, lagged
from sma_fmu.identification.isobaric.model import branch_levels, branch_share
from sma_fmu.identification.isobaric.profile import lagged_basis, wire_rows
from sma_fmu.runtime.constants import BOLTZMANN, COOLING, HEATING, KELVIN_OFFSET, STANDARD_GRAVITY

__all__ = ["file_state", "file_model", "file_jacobian", "through_temperature"]


def file_state(x, layout, f):
    """(profile, tau, wire, direction, level, bounds) of file ``f`` at the vector ``x``."""
    profile = f.profile.basis @ x[layout.knots[f.index]]
    tau = x[layout.lags[f.index]] if layout.lags[f.index] is not None else 0.0
    wire = lagged(profile, tau, f.step)
    direction, level, bounds = wire_rows(wire, f.data.branches, f.per_cycle)
    return profile, tau, wire, direction, level, bounds


def file_model(params, data, wire, levels, direction, level, per_cycle=True):
    """(strain [1], resistance [ohm] or None) of the model at the ``wire`` temperatures
    [degC], per-row branch ``direction`` and residual-strain ``level``."""
    strain = np.empty(wire.size)
    resistance = np.empty(wire.size) if data.resistance is not None else None
    levels = np.asarray(levels, dtype=float)
    for d in (HEATING, COOLING):
        rows = direction == d
        if not rows.any():
            continue
        lv = branch_levels(data.load, d, params, data.reference_length)
        q = branch_share(wire[rows], lv.constants)
        at = level[rows]
        offset = levels[np.minimum(at, levels.size - 1)]
        if d == COOLING and per_cycle:
            offset = offset + (levels[np.minimum(at + 1, levels.size - 1)] - offset) * q
        strain[rows] = lv.strain_hot + lv.strain_span * q + offset
        if resistance is not None:
            resistance[rows] = lv.resistance_hot + lv.resistance_span * q
    return strain, resistance


def through_temperature(params, f, wire, levels, direction, level):
    """(d strain/dT [1/K], d resistance/dT [ohm/K] or None) per sample at the wire temperature."""
    d_strain = np.zeros(wire.size)
    d_resistance = np.zeros(wire.size) if f.data.resistance is not None else None
    for d in (HEATING, COOLING):
        rows = np.nonzero(direction == d)[0]
        if rows.size == 0:
            continue
        lv = branch_levels(f.data.load, d, params, f.data.reference_length)
        c = lv.constants
        q = branch_share(wire[rows], c)
        dq_dt = -q * (1.0 - q) * c.energy_over_kB / (wire[rows] + KELVIN_OFFSET) ** 2
        gain = np.full(rows.size, lv.strain_span)
        if d == COOLING and f.per_cycle:
            at = level[rows]
            gain = gain + levels[np.minimum(at + 1, levels.size - 1)] - levels[at]
        d_strain[rows] = gain * dq_dt
        if d_resistance is not None:
            d_resistance[rows] = lv.resistance_span * dq_dt
    return d_strain, d_resistance


def _parameter_columns(x, layout, f, wire, direction, level):
    """Dense (samples x physical) derivatives of strain and resistance, and the offset entries."""
    params = layout.params(x)
    col = {name: i for i, name in enumerate(layout.phys)}
    n, k = wire.size, len(layout.phys)
    strain = np.zeros((n, k))
    resistance = np.zeros((n, k)) if f.data.resistance is not None else None
    levels = layout.levels(x, f.index)
    first, count, fixed = layout.offsets[f.index]
    off_rows, off_cols, off_values = [], [], []
    per_kb = STANDARD_GRAVITY * f.data.load / (params.N * BOLTZMANN)
    reference = f.data.reference_length
    for d, a, b in ((HEATING, "a_h", "b_h"), (COOLING, "a_c", "b_c")):
        rows = np.nonzero(direction == d)[0]
        if rows.size == 0:
            continue
        lv = branch_levels(f.data.load, d, params, reference)
        c = lv.constants
        energy = c.energy_over_kB
        q = branch_share(wire[rows], c)
        slope_q = -q * (1.0 - q)
        dq_tau = slope_q * (-energy * c.inv_centre_K ** 2)
        dq_e = slope_q * (c.inv_centre_K - 1.0 / (wire[rows] + KELVIN_OFFSET))
        at = level[rows]
        gain = np.full(rows.size, lv.strain_span)
        weights = {0: np.ones(rows.size)}
        if d == COOLING and f.per_cycle:
            gain = gain + levels[np.minimum(at + 1, levels.size - 1)] - levels[at]
            weights = {0: 1.0 - q, 1: q}
        d_energy = {"nu": energy / params.nu, "l_MF": params.nu * per_kb,
                    "x_min": -params.nu * per_kb}
        xi = c.xi_F_min
        d_hot = {"l_MF": xi / reference, "x_min": (1.0 - xi) / reference}
        d_span = {"l_MF": c.M / reference, "x_min": -c.M / reference}
        for name, i in col.items():
            if name in (a, b):
                factor = 1.0 if name == a else f.data.load
                strain[rows, i] = gain * dq_tau * factor
                if resistance is not None:
                    resistance[rows, i] = lv.resistance_span * dq_tau * factor
            elif name in d_energy:
                through_e = dq_e * d_energy[name]
                strain[rows, i] = gain * through_e + d_hot.get(name, 0.0) + d_span.get(name, 0.0) * q
                if resistance is not None:
                    resistance[rows, i] = lv.resistance_span * through_e
            elif name == "R_P" and resistance is not None:
                resistance[rows, i] = (1.0 - xi) - c.M * q
            elif name == "R_MF" and resistance is not None:
                resistance[rows, i] = xi + c.M * q
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
    for dense, slope, sigma, offs in ((strain, d_strain, f.sigma["strain"], offsets),
                                      (resistance, d_resistance, f.sigma.get("resistance"), None)):
        if dense is None:
            continue
        extra = [(lag_b.row, knots.start + lag_b.col, slope[lag_b.row] * lag_b.data)]
        if d_wire_d_tau is not None:
            extra.append((np.arange(n), np.full(n, layout.lags[f.index]), slope * d_wire_d_tau))
        blocks.append(_block(dense, offs, extra, n, size) / sigma)
    return blocks
