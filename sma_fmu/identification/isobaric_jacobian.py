"""Closed-form Jacobian of the isobaric fit's residuals (one file's rows, dense).

With q = 1/(1 + e^Lambda), Lambda = E (1/tau_K - 1/T_K), E = nu (eps_T - g f x_T/N)/k_B and
x_T = x_min - l_MF, the strain residual eps_hot + (span + d_offset) q + offset - data
differentiates through q (dq/dLambda = -q(1-q)) into tau (a, b), E (nu, l_MF, x_min) and the
profile temperature T (the knots, through the interpolation basis), and directly into the
levels (l_MF, x_min, R_P, R_MF) and the offsets. tests/test_isobaric.py checks it against
central differences.
"""
import numpy as np

from sma_fmu.identification.isobaric_model import branch_levels, branch_share
from sma_fmu.runtime.constants import BOLTZMANN, COOLING, HEATING, KELVIN_OFFSET, STANDARD_GRAVITY

__all__ = ["jacobian_rows"]


def jacobian_rows(x, layout, data, index, column, s):
    """Dense Jacobian rows of one file's residual blocks (temperature, strain, resistance)."""
    params = layout.params(x)
    col = {name: i for i, name in enumerate(layout.phys)}
    n = data.temperature.size
    knots = slice(column, column + data.knot_count)
    basis = data.basis.toarray()
    profile = basis @ x[knots]
    levels = layout.levels(x, index)
    first, count, fixed = layout.offsets[index]
    temperature_rows = np.zeros((n, layout.size))
    temperature_rows[:, knots] = basis / s["temperature"]
    strain_rows = np.zeros((n, layout.size))
    resistance_rows = np.zeros((n, layout.size)) if data.resistance is not None else None
    per_kb = STANDARD_GRAVITY * data.load / (params.N * BOLTZMANN)
    reference = data.reference_length
    for d, a, b in ((HEATING, "a_h", "b_h"), (COOLING, "a_c", "b_c")):
        rows = np.nonzero(data.row_direction == d)[0]
        if rows.size == 0:
            continue
        lv = branch_levels(data.load, d, params, reference)
        c = lv.constants
        energy = c.energy_over_kB
        t_k = profile[rows] + KELVIN_OFFSET
        q = branch_share(profile[rows], c)
        slope_q = -q * (1.0 - q)                       # dq/dLambda
        d_lambda = {"T": energy / t_k ** 2, "tau": -energy * c.inv_centre_K ** 2,
                    "E": c.inv_centre_K - 1.0 / t_k}
        level = data.row_level[rows]
        gain = np.full(rows.size, lv.strain_span)     # d eps / dq
        if d == COOLING and data.per_cycle:
            gain = gain + levels[level + 1] - levels[level]
            offset_weight = {0: 1.0 - q, 1: q}
        else:
            offset_weight = {0: np.ones(rows.size)}
        dq = {"tau": slope_q * d_lambda["tau"], "E": slope_q * d_lambda["E"]}
        d_energy = {"nu": energy / params.nu, "l_MF": params.nu * per_kb,
                    "x_min": -params.nu * per_kb}
        xi = c.xi_F_min
        d_hot = {"l_MF": xi / reference, "x_min": (1.0 - xi) / reference}
        d_span = {"l_MF": c.M / reference, "x_min": -c.M / reference}
        block = np.zeros((rows.size, layout.size))
        r_block = np.zeros((rows.size, layout.size)) if resistance_rows is not None else None
        for name, i in col.items():
            if name in (a, b):
                factor = 1.0 if name == a else data.load
                block[:, i] = gain * dq["tau"] * factor
                if r_block is not None:
                    r_block[:, i] = lv.resistance_span * dq["tau"] * factor
            elif name in d_energy:
                through_e = dq["E"] * d_energy[name]
                block[:, i] = gain * through_e + d_hot.get(name, 0.0) + d_span.get(name, 0.0) * q
                if r_block is not None:
                    r_block[:, i] = lv.resistance_span * through_e
            elif name == "R_P" and r_block is not None:
                r_block[:, i] = (1.0 - xi) - c.M * q
            elif name == "R_MF" and r_block is not None:
                r_block[:, i] = xi + c.M * q
        for shift, weight in offset_weight.items():
            target = level + shift - fixed
            ok = target >= 0
            np.add.at(block, (np.nonzero(ok)[0], first + target[ok]), weight[ok])
        dq_dt = slope_q * d_lambda["T"]
        block[:, knots] = (gain * dq_dt)[:, None] * basis[rows]
        strain_rows[rows] = block / s["strain"]
        if r_block is not None:
            r_block[:, knots] = (lv.resistance_span * dq_dt)[:, None] * basis[rows]
            resistance_rows[rows] = r_block / s["resistance"]
    blocks = [temperature_rows, strain_rows]
    if resistance_rows is not None:
        blocks.append(resistance_rows)
    return blocks
