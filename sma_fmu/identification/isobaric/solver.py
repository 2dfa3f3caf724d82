"""Levenberg-Marquardt with sparse direct steps, for the isobaric fit's large sparse problems.

scipy's ``least_squares`` offers exact trust-region steps only for dense Jacobians, and its
iterative (lsmr) steps need thousands of inner iterations on this ill-conditioned problem
(the lag trades against the centres and the profile's knots). Here every step solves the
damped normal equations (J^T J + lambda diag(J^T J)) dx = -J^T r with scipy's sparse LU
(``splu``), so a 26,000-sample, 100-cycle fit with ~1,000 unknowns takes seconds. Bounds
are kept by projecting each trial point onto the box, and an unknown on a bound whose
gradient points out of the box is held there for the step (an active set), so the others
move as if it were fixed (Marquardt's scaling makes the step invariant to the unknowns'
units). Stops when three steps in a row lower the cost by less
than ``ftol`` relative, a step moves every unknown by less than ``xtol`` relative, or after
``max_evaluations``.
"""
from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse import linalg

__all__ = ["Solution", "OrderedLU", "levenberg_marquardt"]


@dataclass
class Solution:
    """What :func:`levenberg_marquardt` found (fields named as scipy's OptimizeResult)."""

    x: np.ndarray
    fun: np.ndarray
    cost: float          # 0.5 * sum(fun^2)
    nfev: int
    status: int          # > 0 converged, 0 evaluation limit
    message: str


class OrderedLU:
    """Sparse LU of a symmetric matrix with its rows and columns taken in ``order`` (None:
    SuperLU's own COLAMD ordering). Ordered by time with the few dense unknowns last, the
    isobaric normal matrix is banded with a dense border, and its factors stay sparse."""

    def __init__(self, matrix, order=None):
        self.order = order
        if order is None:
            self.lu = linalg.splu(matrix.tocsc())
        else:
            # symmetric positive definite: diagonal pivots keep the band
            self.lu = linalg.splu(matrix.tocsr()[order][:, order].tocsc(), permc_spec="NATURAL",
                                  diag_pivot_thresh=0.0, options={"SymmetricMode": True})

    def solve(self, rhs):
        if self.order is None:
            return self.lu.solve(rhs)
        out = np.empty_like(rhs, dtype=float)
        out[self.order] = self.lu.solve(np.asarray(rhs, dtype=float)[self.order])
        return out


def _step(normal, gradient, damping, order, active):
    """The damped step of the free unknowns; the ``active`` ones (on a bound, the gradient
    pushing outward) stay where they are."""
    diagonal = np.maximum(normal.diagonal(), 1e-12 * max(normal.diagonal().max(), 1e-300))
    damped = normal + sparse.diags(damping * diagonal)
    if active.any():
        free = sparse.diags((~active).astype(float))
        damped = free @ damped @ free + sparse.diags(active.astype(float))
        gradient = np.where(active, 0.0, gradient)
    try:
        return -OrderedLU(damped.tocsc(), order).solve(gradient)
    except RuntimeError:           # exactly singular: damp harder
        return None


def levenberg_marquardt(fun, jac, x0, lower, upper, max_evaluations=300, ftol=1e-10,
                        xtol=1e-10, damping=1e-3, order=None):
    """Minimise 0.5 |fun(x)|^2 for ``lower <= x <= upper``; ``jac`` returns a sparse matrix;
    ``order``: the unknowns' elimination order for the sparse LU (see :class:`OrderedLU`)."""
    x = np.clip(np.asarray(x0, dtype=float), lower, upper)
    r = fun(x)
    cost, evaluations, small = 0.5 * float(r @ r), 1, 0
    j = jac(x)
    normal = None
    while evaluations < max_evaluations:
        gradient = j.T @ r
        if normal is None:
            normal = (j.T @ j).tocsc()
        active = ((x <= lower) & (gradient > 0)) | ((x >= upper) & (gradient < 0))
        step = _step(normal, gradient, damping, order, active)
        if step is None or not np.all(np.isfinite(step)):
            damping *= 10.0
            if damping > 1e12:
                return Solution(x, r, cost, evaluations, 2, "the damped step is not finite")
            continue
        trial = np.clip(x + step, lower, upper)
        r_trial = fun(trial)
        evaluations += 1
        cost_trial = 0.5 * float(r_trial @ r_trial)
        if np.isfinite(cost_trial) and cost_trial <= cost:
            decrease = cost - cost_trial
            moved = np.max(np.abs(trial - x) / np.maximum(np.abs(x), 1e-8))
            x, r, cost = trial, r_trial, cost_trial
            damping = max(damping / 3.0, 1e-12)
            small = small + 1 if decrease <= ftol * cost else 0
            if small >= 3:    # three steps in a row: one small step may be a curved valley's
                return Solution(x, r, cost, evaluations, 2, "the cost changes by less than ftol")
            if moved <= xtol:
                return Solution(x, r, cost, evaluations, 3, "the unknowns change by less than xtol")
            j, normal = jac(x), None
        else:
            damping *= 4.0
            if damping > 1e12:
                return Solution(x, r, cost, evaluations, 1, "no step lowers the cost")
    return Solution(x, r, cost, evaluations, 0, "the evaluation limit was reached")
