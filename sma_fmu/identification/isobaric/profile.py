"""The temperature the wire had: a smooth profile of the measured temperature, then the lag.

Two pieces, so that the wire temperature can absorb model misfit only as far as the
thermocouple's noise allows:

1. Profile: the measured temperature is fitted alone by a piecewise-linear curve in time (in
   the sample index without a time column) with knots at the branches' turning points, at
   the corners where a ramp leaves or reaches a dwell, and k evenly spaced knots on each
   ramp; k is chosen from the temperature itself by Akaike's information criterion
   (n ln(RSS/n) + 2 knots), so a linear furnace ramp gets few knots and a curved one more.
   (The Bayesian criterion's heavier penalty left dwell corners unresolved, and that
   systematic error biased the transition width.) For the joint fit a knot is added
   wherever the strain has moved STRAIN_KNOT_SHARE of its branch's span since the last one
   (:func:`strain_knots`): where the strain is steep it tells the wire's temperature far
   better than the thermocouple does, and a latent-heat plateau of a few samples there is
   then followed, not averaged over (not when a lag is fitted: near the turns such knots
   would let the profile mimic the lag). Its knots are fitted jointly with the parameters, held
   to the measured temperature by its noise (:mod:`sma_fmu.identification.isobaric`).
2. Wire: the profile lagged by the fitted time constant
   (:mod:`sma_fmu.identification.isobaric.lag`). The wire's branches turn where the wire
   does, after the thermocouple: :func:`wire_rows` moves each turning point to the wire's
   extremum.
"""
from dataclasses import dataclass

import numpy as np
from scipy import signal, sparse
from scipy.sparse import linalg

from sma_fmu.identification.isobaric.lag import lagged

__all__ = ["Profile", "temperature_profile", "strain_knots", "pointwise_error", "wire_rows",
           "lagged_basis", "INTERIOR_KNOTS", "STRAIN_KNOT_SHARE"]

INTERIOR_KNOTS = (0, 1, 2, 3, 4, 6, 8, 12, 16, 24)   # candidates per branch
STRAIN_KNOT_SHARE = 0.02   # a knot where the strain has moved this share of its branch's span


@dataclass
class Profile:
    """Smoothed measured temperature [degC] at each sample and what it rests on."""

    values: np.ndarray
    basis: object              # sparse (samples x knots) linear interpolation
    knots: np.ndarray          # sample index of each knot
    knots_per_branch: int
    residual_rms: float        # measured - profile [K]
    sigma: float               # residual standard deviation [K] (dof-corrected)
    factor: object             # splu of B^T B (least-squares knots of the temperature alone)
    left: np.ndarray           # per sample: the knot on its left (column of the basis)
    weight: np.ndarray         # per sample: the right knot's weight

    @property
    def knot_count(self):
        return self.basis.shape[1]


def _basis(axis, knots):
    """(sparse basis, left knot of each sample, weight of the right knot)."""
    at = axis[knots]
    k = np.clip(np.searchsorted(at, axis, side="right") - 1, 0, at.size - 2)
    w = (axis - at[k]) / (at[k + 1] - at[k])
    rows = np.arange(axis.size)
    return sparse.csr_matrix((np.concatenate([1 - w, w]), (np.concatenate([rows, rows]),
                                                           np.concatenate([k, k + 1]))),
                             shape=(axis.size, at.size)), k, w


def _corners(temperature, branches, window):
    """(first, last) sample of each branch's ramp: the largest curvature of the temperature
    (Savitzky-Golay second derivative over ``window`` samples, whose response to a kink is
    symmetric about it) in the first and in the second half of the branch. On a ramp between
    dwells these are the dwell corners; on a triangle they fall near the turning points."""
    window = max(5, int(window) | 1)
    if temperature.size <= window:
        return [(b.start, b.stop - 1) for b in branches]
    curvature = np.abs(signal.savgol_filter(temperature, window, 2, deriv=2, mode="interp"))
    curvature[:window // 2] = curvature[-(window // 2):] = 0.0   # the filter's edge fits
    out = []
    for b in branches:
        half = (b.stop - b.start) // 2
        if half < 2:
            out.append((b.start, b.stop - 1))
            continue
        out.append((b.start + int(np.argmax(curvature[b.start:b.start + half])),
                    b.start + half + int(np.argmax(curvature[b.start + half:b.stop]))))
    return out


def _knots(branches, ramps, size, interior):
    knots = {0, size - 1}
    for b, (first, last) in zip(branches, ramps):
        knots.update((b.start, b.stop - 1))
        knots.update(np.linspace(first, last, interior + 2).round().astype(int).tolist())
    return np.array(sorted(knots))


def strain_knots(strain, branches, share=STRAIN_KNOT_SHARE):
    """Sample indices where the strain has moved ``share`` of its branch's span since the
    previous such sample (or the branch's start)."""
    out = []
    for b in branches:
        e = strain[b.start:b.stop]
        span = float(np.ptp(e)) if e.size else 0.0
        if not span > 0:
            continue
        last = e[0]
        for i in range(1, e.size - 1):
            if abs(e[i] - last) > share * span:
                out.append(b.start + i)
                last = e[i]
    return np.array(out, dtype=int)


def _least_squares(axis, knots, temperature):
    basis, left, weight = _basis(axis, knots)
    factor = linalg.splu((basis.T @ basis).tocsc())
    values = basis @ factor.solve(basis.T @ temperature)
    return basis, left, weight, factor, values, float(np.sum((temperature - values) ** 2))


def temperature_profile(temperature, branches, time=None, window=5, strain=None):
    """:class:`Profile` of the measured ``temperature`` [degC], knots chosen by AIC.

    Knots: each branch's turning points, the corners where its ramp leaves and reaches a
    dwell (found on the temperature smoothed over ``window`` samples), and ``k`` evenly
    spaced knots on the ramp; with ``strain`` [1] also :func:`strain_knots`.
    """
    n = temperature.size
    axis = np.asarray(time, dtype=float) if time is not None else np.arange(n, dtype=float)
    ramps = _corners(temperature, branches, window)
    shortest = min(b.stop - b.start for b in branches)
    best = None
    for interior in INTERIOR_KNOTS:
        if interior > 0 and (interior + 1) * 3 > shortest:
            break
        knots = _knots(branches, ramps, n, interior)
        basis, left, weight, factor, values, rss = _least_squares(axis, knots, temperature)
        aic = n * np.log(max(rss, 1e-300) / n) + 2.0 * basis.shape[1]
        if best is None or aic < best[0]:
            best = (aic, interior, basis, factor, values, rss, knots, left, weight)
    _, interior, basis, factor, values, rss, knots, left, weight = best
    if strain is not None:
        knots = np.union1d(knots, strain_knots(strain, branches))
        basis, left, weight, factor, values, rss = _least_squares(axis, knots, temperature)
    dof = max(n - basis.shape[1], 1)
    return Profile(values, basis, knots, interior, float(np.sqrt(rss / n)),
                   float(np.sqrt(rss / dof)), factor, left, weight)


def pointwise_error(profile):
    """Standard error [K] of the profile at each sample: sigma sqrt(b_i^T (B^T B)^-1 b_i),
    with b_i the sample's two interpolation weights. B^T B is tridiagonal (hat functions),
    so the inverse's diagonal and first off-diagonal come from its LDL^T factors in one
    backward sweep (Takahashi's recurrence)."""
    normal = (profile.basis.T @ profile.basis).tocsr()
    a, b = normal.diagonal(), normal.diagonal(1)
    count = a.size
    d, ratio = np.empty(count), np.empty(max(count - 1, 0))
    d[0] = a[0]
    for i in range(count - 1):
        ratio[i] = b[i] / d[i]
        d[i + 1] = a[i + 1] - ratio[i] * b[i]
    diagonal, upper = np.empty(count), np.zeros(count)
    diagonal[-1] = 1.0 / d[-1]
    for i in range(count - 2, -1, -1):
        upper[i] = -ratio[i] * diagonal[i + 1]
        diagonal[i] = 1.0 / d[i] - ratio[i] * upper[i]
    k, w = profile.left, profile.weight
    leverage = (1 - w) ** 2 * diagonal[k] + 2 * w * (1 - w) * upper[k] + w ** 2 * diagonal[k + 1]
    return profile.sigma * np.sqrt(np.clip(leverage, 0.0, None))


def wire_rows(wire, branches, levels_per_cycle=True):
    """(direction, level, bounds) per sample of the lagged ``wire`` temperature; bounds are
    the wire branches' first rows and the end.

    Each turning point of the measured branches moves forward to the wire's extremum,
    searched over the first half of the next branch.
    """
    n = wire.size
    bounds = [0]
    for previous, b in zip(branches, branches[1:]):
        stop = b.start + max(1, (b.stop - b.start) // 2)
        window = wire[b.start:stop] * previous.direction
        bounds.append(b.start + int(np.argmax(window)))
    bounds.append(n)
    index = np.zeros(n, dtype=int)
    for k, start in enumerate(bounds[1:-1], start=1):
        index[start:] = k
    direction = np.array([b.direction for b in branches])[index]
    level = np.array([b.level if levels_per_cycle else 0 for b in branches])[index]
    return direction, level, bounds



def lagged_basis(profile, tau, step):
    """Sparse lagged(B) (samples x knots) of a :class:`Profile`: each hat function's lagged
    response, cut where the exponential tail has fallen below 1e-12 of its height (all hat
    functions at once, one row each of a padded block)."""
    if not tau > 0:
        return profile.basis
    n, count = profile.basis.shape
    knots = profile.knots
    tail = int(np.ceil(28.0 * tau / step)) + 2 if tau > 0 else 1
    first = np.concatenate([[0], knots[:-1]])
    stop = np.minimum(n, np.concatenate([knots[1:], [n - 1]]) + tail)
    rows = first[:, None] + np.arange(int((stop - first).max()))[None, :]
    inside = rows < stop[:, None]
    rows = np.minimum(rows, n - 1)
    column = np.arange(count)[:, None]
    left, weight = profile.left[rows], profile.weight[rows]
    hat = np.where(left == column, 1.0 - weight, np.where(left + 1 == column, weight, 0.0))
    response = lagged(np.where(inside, hat, 0.0), tau, step)
    keep = inside & (np.abs(response) > 1e-12)
    return sparse.csr_matrix((response[keep], (rows[keep], np.broadcast_to(column, rows.shape)[keep])),
                             shape=(n, count))
