"""Half-strain temperatures: where a branch has gone half way from one baseline to the other.

On one branch, the baselines are the tangent construction's sloped lines through the
martensite (cold) and austenite (hot) ends
(:func:`sma_fmu.identification.transformation_temperatures.branch_tangents`); the progress of
a sample is (strain - hot line)/(cold line - hot line) at its temperature, and the
half-strain temperature is the median temperature of the samples within 5 % of progress 1/2
(a noise-free curve: linear interpolation of the crossing). Used by ``fit isobaric`` (data and
model at every stress, and their slopes against stress) and by ``predict isobaric``.
"""
import math

import numpy as np

from sma_fmu.identification.transformation_temperatures import branch_tangents

__all__ = ["half_strain_temperature", "stress_slope"]


def half_strain_temperature(temperature, strain, direction):
    """Half-strain temperature [degC] of one branch, or NaN when it shows no transformation."""
    found = branch_tangents(temperature, strain, direction)
    if found is None:
        return math.nan
    order = np.argsort(temperature, kind="stable")
    t = np.asarray(temperature, dtype=float)[order]
    e = np.asarray(strain, dtype=float)[order]
    cold = found["cold"][0] + found["cold"][1] * t
    hot = found["hot"][0] + found["hot"][1] * t
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
