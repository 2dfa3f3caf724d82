"""Bounded, scaled least squares over a subset of the wire parameters (scipy), with statistics.

The objective maps a parameter vector to residuals (model - data) of the pure model;
parameters are scaled by their starting values so every unknown is of order one.
Standard errors come from the Jacobian at the solution: cov = s^2 (J^T J)^-1 with
s^2 = sum(r^2)/(m - n); 95 % intervals use Student's t with m - n degrees of freedom.
"""
import time
from dataclasses import dataclass

import numpy as np
from scipy import optimize, stats

__all__ = ["FitParameter", "FitResult", "fit_parameters", "percentage_errors"]


@dataclass(frozen=True)
class FitParameter:
    """One unknown: a WireParameters name, its starting value and bounds (same unit)."""

    name: str
    start: float
    lower: float
    upper: float


@dataclass
class FitResult:
    """Outcome of :func:`fit_parameters`."""

    params: object               # WireParameters with the fitted values
    parameters: list             # the FitParameter unknowns
    values: np.ndarray
    std_errors: np.ndarray
    ci95: np.ndarray             # shape (n, 2)
    covariance: np.ndarray       # shape (n, n), physical units, order of ``parameters``
    residuals: np.ndarray        # model - data at the solution
    cost: float
    evaluations: int
    converged: bool
    message: str
    seconds: float

    def table(self):
        """Per parameter: {value, start, std_error, ci95, at_bound} (JSON-ready)."""
        rows = {}
        for p, value, error, (low, high) in zip(self.parameters, self.values, self.std_errors,
                                                self.ci95):
            span = p.upper - p.lower
            rows[p.name] = {"value": float(value), "start": p.start, "std_error": float(error),
                            "ci95": [float(low), float(high)],
                            "at_bound": bool(min(value - p.lower, p.upper - value) < 1e-9 * span)}
        return rows

    def covariance_table(self):
        """{"parameters": names, "matrix": rows} of the estimates' covariance (JSON-ready).

        ``matrix[i][j]`` = cov(p_i, p_j) in the product of the two parameters' units;
        its diagonal is the square of the standard errors.
        """
        return {"parameters": [p.name for p in self.parameters],
                "matrix": [[float(v) for v in row] for row in self.covariance]}


def fit_parameters(residuals_of, base, parameters, max_evaluations=2000):
    """Least squares over ``parameters`` starting from ``base`` (a WireParameters).

    ``residuals_of(params)`` returns the residual array [ohm] for a WireParameters.
    """
    names = [p.name for p in parameters]
    scale = np.array([abs(p.start) if p.start != 0 else 1.0 for p in parameters])
    start = np.array([p.start for p in parameters]) / scale
    lower = np.array([p.lower for p in parameters]) / scale
    upper = np.array([p.upper for p in parameters]) / scale

    def residuals(x):
        return residuals_of(base.replace(**dict(zip(names, (x * scale).tolist()))))

    began = time.perf_counter()
    solution = optimize.least_squares(residuals, np.clip(start, lower, upper), bounds=(lower, upper),
                                      method="trf", x_scale=1.0, xtol=1e-15, ftol=1e-15,
                                      gtol=1e-15, max_nfev=max_evaluations)
    seconds = time.perf_counter() - began
    values = solution.x * scale
    m, n = solution.fun.size, len(names)
    dof = max(m - n, 1)
    variance = float(np.sum(solution.fun ** 2)) / dof
    # covariance in the scaled unknowns (well conditioned), then back to physical units
    scaled = variance * np.linalg.pinv(solution.jac.T @ solution.jac)
    scaled = 0.5 * (scaled + scaled.T)   # pinv is symmetric only to rounding; a covariance is exactly
    covariance = scaled * np.outer(scale, scale)
    std_errors = np.sqrt(np.clip(np.diag(covariance), 0.0, None))
    half = stats.t.ppf(0.975, dof) * std_errors
    return FitResult(
        params=base.replace(**dict(zip(names, values.tolist()))), parameters=list(parameters),
        values=values, std_errors=std_errors, ci95=np.column_stack([values - half, values + half]),
        covariance=covariance,
        residuals=solution.fun, cost=float(solution.cost), evaluations=int(solution.nfev),
        converged=bool(solution.status > 0), message=str(solution.message), seconds=seconds)


def percentage_errors(model, data):
    """Absolute percentage errors |model - data| / data * 100 [%] (data > 0)."""
    return 100.0 * np.abs(np.asarray(model) - np.asarray(data)) / np.asarray(data)
