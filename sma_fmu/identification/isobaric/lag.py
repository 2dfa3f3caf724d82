"""First-order lag of the wire behind the measured (thermocouple) temperature.

The thermocouple sits beside the wire, not in it: the wire follows the temperature u it
reads with a time constant tau,  dw/dt = (u - w) / tau. Between samples u is taken as
linear (the fit's temperature profile is piecewise linear), and then the exact solution
over one step h is the ramp-invariant recursion

    w_i = a w_{i-1} + (1 - c) u_i + (c - a) u_{i-1},   a = exp(-h/tau),  c = tau (1 - a)/h,

started in equilibrium (w_0 = u_0). tau = 0 gives w = u. The step h is uniform: seconds
(the median step of a time column) or 1 when the file has no time column, so tau is then
counted in samples. The recursion runs as scipy's ``signal.lfilter``; :func:`lag_adjoint`
is its transpose (used for the covariance), :func:`lag_derivative` its derivative in tau.
"""
import math

import numpy as np
from scipy import signal

__all__ = ["lag_coefficients", "lagged", "lag_adjoint", "lag_derivative", "uniform_step"]


def lag_coefficients(tau, step=1.0):
    """(a, b0, b1) of the recursion for time constant ``tau`` and ``step`` (same unit)."""
    if not tau > 0.0:
        return 0.0, 1.0, 0.0
    a = math.exp(-step / tau)
    c = tau * (1.0 - a) / step
    return a, 1.0 - c, c - a


def lagged(u, tau, step=1.0):
    """Wire temperature w (array like ``u`` [degC], lagged along its last axis) lagging ``u``
    by ``tau`` (unit of ``step``)."""
    u = np.asarray(u, dtype=float)
    a, b0, b1 = lag_coefficients(tau, step)
    if a == 0.0 and b1 == 0.0 or u.shape[-1] < 2:
        return u.copy()
    out = np.empty_like(u)
    out[..., 0] = u[..., 0]
    out[..., 1:], _ = signal.lfilter([b0, b1], [1.0, -a], u[..., 1:],
                                     zi=(b1 + a) * u[..., :1])
    return out


def lag_adjoint(y, tau, step=1.0):
    """Transpose of :func:`lagged` applied to ``y``: sum(y * lagged(u)) = sum(lag_adjoint(y) * u)."""
    y = np.asarray(y, dtype=float)
    a, b0, b1 = lag_coefficients(tau, step)
    if a == 0.0 and b1 == 0.0 or y.size < 2:
        return y.copy()
    # lam_i = y_i + a lam_{i+1}: the sensitivity of sum(y w) to the state w_i
    lam = signal.lfilter([1.0], [1.0, -a], y[::-1])[::-1]
    out = np.zeros_like(y)
    out[1:] += b0 * lam[1:]
    out[:-1] += b1 * lam[1:]
    out[0] += lam[0]                  # w_0 = u_0 (lam_0 carries its effect on w_1 ...)
    return out


def lag_derivative(u, tau, step=1.0):
    """d lagged(u, tau) / d tau (central difference; the lag is smooth in tau)."""
    h = 1e-4 * max(tau, 1e-2 * step)
    low = max(tau - h, 0.0)
    return (lagged(u, tau + h, step) - lagged(u, low, step)) / (tau + h - low)


def uniform_step(time):
    """(step, spread): the median step of a time column [s] (1 sample without one) and the
    largest relative deviation of a step from it."""
    if time is None:
        return 1.0, 0.0
    steps = np.diff(np.asarray(time, dtype=float))
    step = float(np.median(steps))
    return step, float(np.max(np.abs(steps - step)) / step) if steps.size else 0.0
