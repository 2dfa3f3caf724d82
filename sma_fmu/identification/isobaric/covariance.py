"""Covariance of the isobaric fit's unknowns, and its map onto parameter-file names."""
import numpy as np
from scipy import sparse

from sma_fmu.identification.isobaric.solver import OrderedLU

__all__ = ["reported_covariance", "named", "named_values", "wire_covariance"]


def reported_covariance(jac, factor, count, order):
    """(s^2 (J^T J)^-1 restricted to the first ``count`` unknowns, the boolean mask of those
    no residual touches) (sparse LU of the scaled normal matrix; a tiny ridge keeps unvisited
    levels from making it singular). An unknown no residual touches (the level of a left-out
    cycle) is decoupled and gets a unit diagonal; the caller reports it as undetermined."""
    normal = (jac.T @ jac).tocsc()
    dead = normal.diagonal() == 0.0
    if dead.any():
        normal = normal + sparse.diags(dead.astype(float))
    scale = np.sqrt(np.clip(normal.diagonal(), 1e-300, None))
    scaled = sparse.diags(1 / scale) @ normal @ sparse.diags(1 / scale)
    scaled = scaled + 1e-12 * sparse.identity(scaled.shape[0])
    unit = np.zeros((scaled.shape[0], count))
    unit[np.arange(count), np.arange(count)] = 1.0
    inverse = OrderedLU(scaled, order).solve(unit)[:count]
    return factor * inverse / np.outer(scale[:count], scale[:count]), dead[:count]


def named(layout, vector):
    """(names, matrix): the reported unknowns by parameter-file name (the centres and the
    heating centres' gaps mapped onto a_h, b_h, a_c, b_c), offsets and lags, and the matrix
    taking the internal unknowns' covariance to theirs."""
    phys_names, transform = layout.transform(vector)
    k, p = len(layout.reported), len(layout.phys)
    matrix = np.zeros((len(phys_names) + k - p, k))
    matrix[:len(phys_names), :p] = transform
    matrix[len(phys_names):, p:] = np.eye(k - p)
    return phys_names + list(layout.reported[p:]), matrix


def named_values(layout, vector, names):
    physical = layout.physical(vector)
    p = len(layout.phys)
    rest = list(vector[p:len(layout.reported)])
    return np.array([physical[n] for n in names[:len(names) - len(rest)]] + rest, dtype=float)


def wire_covariance(names, values, cov, layout):
    """Names, values and covariance of the parameter-file entries the unknowns set."""
    out, rows, numbers = [], [], []
    for i, name in enumerate(names):
        if name.startswith(("offset_", "lag_")):
            continue
        pair = {"l_MF": ("l_M", "l_F", layout.half_l), "R_MF": ("R_M", "R_F", layout.half_r)}
        targets = [(pair[name][0], -pair[name][2]), (pair[name][1], pair[name][2])] \
            if name in pair else [(name, 0.0)]
        for target, shift in targets:
            row = np.zeros(cov.shape[0])
            row[i] = 1.0
            out.append(target)
            rows.append(row)
            numbers.append(values[i] + shift)
    transform = np.array(rows)
    return out, np.array(numbers), transform @ cov @ transform.T
