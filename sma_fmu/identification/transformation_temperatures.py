"""Tangent-line transformation temperatures (ASTM E3097-style) of strain-temperature branches.

On one heating or cooling branch:

1. Rough levels: the median strain of the coldest and hottest 10 % of the samples; the
   temperatures T25, T50, T75 where the strain has gone 25, 50, 75 % of the way from one
   level to the other (median temperature of the samples within 5 % of that share; 10 or
   15 % on a steep branch with fewer than two samples there).
2. Baselines: straight lines (least squares) through the samples colder than
   T50 - 2.5 |T75 - T25| (martensite, "cold") and hotter than T50 + 2.5 |T75 - T25|
   (austenite, "hot"); they keep the slope of the data (thermal expansion, creep). Where
   those samples span under a tenth of |T75 - T25| (bunched at a turn) the line is flat
   at their median strain: a slope from them would be noise.
3. Transformation tangent: the tangent at the branch's steepest point (ASTM F2082 / E3097
   practice, and what ASMADA does): a logistic step plus a straight line (scipy's
   ``curve_fit``) is fitted to the branch, and the tangent is taken at the logistic's
   centre, where the fitted curve is steepest. The smooth fit stands in for the noisy
   samples, whose own steepest point noise would pick. Where that fit fails, the straight
   line through the samples between 40 % and 60 % of the way from the hot to the cold
   baseline is used instead (fitted as temperature against strain, because the temperature
   carries the noise).
4. Heating: A_s where the tangent meets the cold baseline, A_f where it meets the hot one;
   cooling: M_s at the hot baseline, M_f at the cold one. The midpoint is where the tangent
   crosses half way between the baselines.

Per cycle (a heating branch and the cooling branch after it):
- thermal hysteresis = midpoint(heating) - midpoint(cooling) [K], the width of the loop at
  half the actuation strain;
- actuation strain = cold baseline at A_s - hot baseline at A_f on heating [1];
- residual strain = cold baseline of the cooling branch minus that of the heating branch,
  both at the cycle's lowest temperature [1]: what the cycle leaves behind (open loop).

E3097 leaves the choice of the linear portions to the operator; these rules are ours.
"""
import math
import warnings

import numpy as np
from scipy import optimize

from sma_fmu.runtime.constants import HEATING

__all__ = ["branch_tangents", "branch_tangents_or_reason", "cycle_numbers", "QUANTITIES", "TAIL_WIDTHS", "BAND"]

BAND = (0.4, 0.6)
TAIL_WIDTHS = 2.5
MIN_BASELINE_POINTS = 5
SHORT_BASELINE = 0.1   # a baseline spanning under this share of T25-T75 is taken flat
QUANTITIES = (("A_s", "degC"), ("A_f", "degC"), ("M_s", "degC"), ("M_f", "degC"),
              ("thermal_hysteresis", "K"), ("actuation_strain", "%"), ("residual_strain", "%"))


def _share_temperature(temperature, share, target):
    """Median temperature of the samples within 5 % of ``target`` (10 or 15 % when a steep,
    sparsely sampled branch leaves fewer than two there)."""
    for band in (0.05, 0.10, 0.15):
        near = np.abs(share - target) <= band
        if near.sum() >= 2:
            return float(np.median(temperature[near]))
    return None


def _line(x, y):
    """(intercept, slope) of y = a + b x, least squares."""
    slope, intercept = np.polyfit(x, y, 1)
    return float(intercept), float(slope)


def _baseline(t, e, width):
    """(intercept, slope) of a baseline: the least-squares line, or flat at the median strain
    where its samples span under SHORT_BASELINE of the transformation's quartile ``width``
    [K] (a few samples bunched at a turn: a slope from them is noise, and extrapolated to
    the branch's coldest point or to the tangent it can give any strain)."""
    if np.ptp(t) < SHORT_BASELINE * width:
        return float(np.median(e)), 0.0
    return _line(t, e)


def _meet(tangent, line):
    """Temperature where T = c + d eps meets eps = a + b T."""
    c, d = tangent
    a, b = line
    return (c + d * a) / (1.0 - d * b)


def _logistic_step(t, low, high, rate, centre, slope):
    """A logistic step from ``low`` to ``high`` [1] around ``centre`` [degC] plus a line."""
    return low + (high - low) / (1.0 + np.exp(-rate * (t - centre))) + slope * (t - centre)


def _steepest_tangent(t, e, cold, hot, t50, width):
    """(intercept [degC], slope [K]) of T = c + d eps at the steepest point of a logistic step
    fitted to the branch, or None when the fit fails or its centre leaves the branch."""
    start = (cold[0] + cold[1] * t50, hot[0] + hot[1] * t50, 4.4 / width, t50,
             0.5 * (cold[1] + hot[1]))
    try:
        with np.errstate(over="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", optimize.OptimizeWarning)
            (low, high, rate, centre, slope), _ = optimize.curve_fit(
                _logistic_step, t, e, p0=start, maxfev=2000)
    except (RuntimeError, ValueError):
        return None
    steepest = (high - low) * rate / 4.0 + slope      # d eps / dT at the centre [1/K]
    if not (t[0] < centre < t[-1]) or not math.isfinite(steepest) or steepest == 0.0:
        return None
    middle = _logistic_step(centre, low, high, rate, centre, slope)
    return centre - middle / steepest, 1.0 / steepest


def branch_tangents(temperature, strain, direction, band=BAND, tail=TAIL_WIDTHS):
    """Tangent-line numbers of one branch, or None when it does not show a transformation.

    ``temperature`` [degC] and ``strain`` [1] are arrays of the branch's samples (any order);
    ``direction`` is +1 (heating) or -1 (cooling). Returns {"start", "finish", "midpoint"
    [degC], "cold", "hot" (intercept [1], slope [1/K]) of the baselines, "tangent"
    (intercept [degC], slope [K]) of T against strain, "lowest" [degC]}.
    """
    return branch_tangents_or_reason(temperature, strain, direction, band, tail)[0]


def branch_tangents_or_reason(temperature, strain, direction, band=BAND, tail=TAIL_WIDTHS):
    """(:func:`branch_tangents` result, None), or (None, why the construction cannot be made)."""
    heating = direction == HEATING
    order = np.argsort(temperature, kind="stable")
    t = np.asarray(temperature, dtype=float)[order]
    e = np.asarray(strain, dtype=float)[order]
    ends = max(3, t.size // 10)
    cold_level, hot_level = float(np.median(e[:ends])), float(np.median(e[-ends:]))
    if not cold_level > hot_level:
        return None, "the strain is not lower hot than cold: no transformation in the branch"
    share = (e - hot_level) / (cold_level - hot_level)
    marks = [_share_temperature(t, share, q) for q in (0.75, 0.5, 0.25)]
    if None in marks:
        return None, "too few samples at 25, 50 or 75 % of the strain change"
    t75, t50, t25 = marks
    width = max(abs(t25 - t75), 1e-6)
    cold_rows, hot_rows = t < t50 - tail * width, t > t50 + tail * width
    if hot_rows.sum() < MIN_BASELINE_POINTS:
        return None, ("transformation not finished before the turn (no austenite baseline)"
                      if heating else "transformation already under way at the branch's "
                      "hottest point (no austenite baseline)")
    if cold_rows.sum() < MIN_BASELINE_POINTS:
        return None, ("transformation already under way at the branch's coldest point (no "
                      "martensite baseline)" if heating else
                      "transformation not finished before the turn (no martensite baseline)")
    cold = _baseline(t[cold_rows], e[cold_rows], width)
    hot = _baseline(t[hot_rows], e[hot_rows], width)
    low_line = hot[0] + hot[1] * t
    with np.errstate(divide="ignore", invalid="ignore"):   # baselines that cross
        progress = (e - low_line) / (cold[0] + cold[1] * t - low_line)
    tangent = _steepest_tangent(t, e, cold, hot, t50, width)
    if tangent is None:
        rows = (progress >= band[0]) & (progress <= band[1])
        if rows.sum() < 2 or np.ptp(e[rows]) == 0.0:
            return None, ("no steepest point (the logistic fit failed) and fewer than 2 "
                          "samples between 40 and 60 % of the transformation")
        tangent = _line(e[rows], t[rows])
    middle = (0.5 * (cold[0] + hot[0]), 0.5 * (cold[1] + hot[1]))
    at_cold, at_hot = _meet(tangent, cold), _meet(tangent, hot)
    start, finish = (at_cold, at_hot) if heating else (at_hot, at_cold)
    return {"start": start, "finish": finish, "midpoint": _meet(tangent, middle), "cold": cold,
            "hot": hot, "tangent": tangent, "lowest": float(t[0])}, None


def cycle_numbers(heating, cooling):
    """{quantity: value} of one cycle from its branches' :func:`branch_tangents` (None allowed).

    Temperatures [degC], hysteresis [K], strains in percent; NaN where a branch is missing.
    """
    nan = math.nan
    out = {name: nan for name, _ in QUANTITIES}
    if heating:
        out["A_s"], out["A_f"] = heating["start"], heating["finish"]
        cold, hot = heating["cold"], heating["hot"]
        out["actuation_strain"] = 100.0 * ((cold[0] + cold[1] * heating["start"])
                                           - (hot[0] + hot[1] * heating["finish"]))
    if cooling:
        out["M_s"], out["M_f"] = cooling["start"], cooling["finish"]
    if heating and cooling:
        out["thermal_hysteresis"] = heating["midpoint"] - cooling["midpoint"]
        low = heating["lowest"]
        before, after = heating["cold"], cooling["cold"]
        out["residual_strain"] = 100.0 * ((after[0] + after[1] * low) - (before[0] + before[1] * low))
    return out
