"""Half-strain temperatures: where a branch has gone half way from one baseline to the other.

On one branch, the baselines are the tangent construction's sloped lines through the
martensite (cold) and austenite (hot) ends
(:func:`sma_fmu.identification.transformation_temperatures.branch_tangents`); the progress of
a sample is (strain - hot line)/(cold line - hot line) at its temperature (lines through the
coldest and hottest 15 % of the samples where the tangent construction cannot be made), and the
half-strain temperature is the median temperature of the samples within 5 % of progress 1/2
(a noise-free curve: linear interpolation of the crossing). Used by ``fit isobaric`` (data and
model at every stress, and their slopes against stress) and by ``predict isobaric``.
"""
import math

import numpy as np

from sma_fmu.identification.transformation_temperatures import branch_tangents

__all__ = ["baselines", "half_strain_temperature", "transformation_strain", "stress_slope",
           "ENDS"]

ENDS = 0.15   # share of a branch's samples at each end for the fallback baselines


def baselines(temperature, strain, direction):
    """((intercept [1], slope [1/K]) of the cold baseline, the same of the hot one), or None.

    The tangent construction's; where it cannot be made because the transformation is too
    steep for its 40-60 % band (a stepped strain), lines through the coldest and hottest
    ENDS of the samples."""
    found = branch_tangents(temperature, strain, direction)
    if found is not None:
        return found["cold"], found["hot"]
    order = np.argsort(temperature, kind="stable")
    t = np.asarray(temperature, dtype=float)[order]
    e = np.asarray(strain, dtype=float)[order]
    count = max(5, int(ENDS * t.size))
    if t.size < 4 * count:
        return None
    lines = []
    for rows in (slice(0, count), slice(t.size - count, t.size)):
        slope, intercept = np.polyfit(t[rows], e[rows], 1)
        lines.append((float(intercept), float(slope)))
    if not lines[0][0] + lines[0][1] * t.mean() > lines[1][0] + lines[1][1] * t.mean():
        return None
    return lines[0], lines[1]


def transformation_strain(temperature, strain, direction):
    """Strain between the baselines at the half-strain temperature [1], or NaN."""
    lines = baselines(temperature, strain, direction)
    at = half_strain_temperature(temperature, strain, direction)
    if lines is None or not math.isfinite(at):
        return math.nan
    (c0, c1), (h0, h1) = lines
    return float(c0 + c1 * at - h0 - h1 * at)


def half_strain_temperature(temperature, strain, direction):
    """Half-strain temperature [degC] of one branch, or NaN when it shows no transformation."""
    lines = baselines(temperature, strain, direction)
    if lines is None:
        return math.nan
    order = np.argsort(temperature, kind="stable")
    t = np.asarray(temperature, dtype=float)[order]
    e = np.asarray(strain, dtype=float)[order]
    cold = lines[0][0] + lines[0][1] * t
    hot = lines[1][0] + lines[1][1] * t
    with np.errstate(divide="ignore", invalid="ignore"):   # baselines that cross: no progress
        progress = (e - hot) / (cold - hot)
    near = np.abs(progress - 0.5) <= 0.05
    if near.sum() >= 5:
        return float(np.median(t[near]))
    above = np.nonzero(progress >= 0.5)[0]
    if above.size == 0 or above[-1] + 1 >= t.size:
        return math.nan
    i = above[-1]
    p0, p1 = progress[i], progress[i + 1]
    return float(t[i] + (t[i + 1] - t[i]) * (p0 - 0.5) / (p0 - p1)) if p0 != p1 else float(t[i])


def stress_slope(stresses, temperatures):
    """(slope [K/MPa], intercept [degC]) of a straight line through (stress, temperature)
    pairs, NaN with fewer than two finite points at different stresses."""
    s = np.asarray(stresses, dtype=float)
    t = np.asarray(temperatures, dtype=float)
    ok = np.isfinite(t)
    if ok.sum() < 2 or np.ptp(s[ok]) == 0:
        return math.nan, math.nan
    slope, intercept = np.polyfit(s[ok], t[ok], 1)
    return float(slope), float(intercept)
