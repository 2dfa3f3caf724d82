"""Designs of a study: axis points (grid, random, Latin hypercube) and Monte Carlo draws.

Axis values: a list (grid: used as given; random and lhs: picked uniformly), or a range
``{low, high}`` with ``num`` points (grid) and ``log = true`` for log spacing or sampling.
Random points come from ``numpy.random.default_rng(seed)``, Latin-hypercube points from
``scipy.stats.qmc.LatinHypercube(rng=seed)``. Monte Carlo draws come from a multivariate
normal with the estimates and covariance of an identification report (the ``report.json``
of ``sma-fmu fit``), from ``default_rng(seed + 1)``, so they differ from the axes' stream.
"""
import itertools
import json
import math

import numpy as np
from scipy.stats import qmc

__all__ = ["MAX_POINTS", "axis_points", "monte_carlo_draws"]

_RANGE_KEYS = {"low", "high", "num", "log"}
# choice: the most axis points or Monte Carlo draws a study may ask for (and runs in all);
# checked before anything is drawn, so a typo cannot exhaust memory
MAX_POINTS = 1_000_000


def _number(value, where):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{where} must be a finite number, got {value!r}")
    return float(value)


def _range(key, table, kind):
    unknown = sorted(set(table) - _RANGE_KEYS)
    if unknown:
        raise ValueError(f"{key!r}: unknown key(s) {', '.join(unknown)}; expected low, high, "
                         f"num (grid), log")
    for name in ("low", "high") + (("num",) if kind == "grid" else ()):
        if name not in table:
            raise ValueError(f"{key!r}: missing {name}")
    low, high = _number(table["low"], f"{key!r} low"), _number(table["high"], f"{key!r} high")
    log = table.get("log", False)
    if not isinstance(log, bool):
        raise ValueError(f"{key!r}: log must be true or false, got {log!r}")
    if not high >= low or (log and not low > 0.0):
        raise ValueError(f"{key!r}: needs low <= high{' and low > 0 (log)' if log else ''}, "
                         f"got low = {low!r}, high = {high!r}")
    return low, high, log, table.get("num")


def _grid_values(key, spec):
    if isinstance(spec, list):
        if not spec:
            raise ValueError(f"{key!r}: the list of values is empty")
        return list(spec)
    if not isinstance(spec, dict):
        raise ValueError(f"{key!r}: expected a list of values or {{low, high, num}}, got {spec!r}")
    low, high, log, num = _range(key, spec, "grid")
    if isinstance(num, bool) or not isinstance(num, int) or not 1 <= num <= MAX_POINTS:
        raise ValueError(f"{key!r}: num must be a whole number in [1, {MAX_POINTS}], got {num!r}")
    points = np.geomspace(low, high, num) if log else np.linspace(low, high, num)
    return [float(v) for v in points]


def _scale(key, spec, unit_values):
    """Map samples in [0, 1) onto a range or a list of values."""
    if isinstance(spec, list):
        if not spec:
            raise ValueError(f"{key!r}: the list of values is empty")
        return [spec[min(int(u * len(spec)), len(spec) - 1)] for u in unit_values]
    if not isinstance(spec, dict):
        raise ValueError(f"{key!r}: expected {{low, high}} or a list of values, got {spec!r}")
    low, high, log, _ = _range(key, spec, "random")
    if log:
        return [float(math.exp(math.log(low) + u * (math.log(high) - math.log(low))))
                for u in unit_values]
    return [float(low + u * (high - low)) for u in unit_values]


def axis_points(kind, axes, samples, seed):
    """({key: values}, [{key: value} per point]) of the axes ``{key: spec}``.

    ``kind`` is "grid" (every combination, keys in order), "random" or "lhs" (``samples``
    points).
    """
    if not isinstance(axes, dict):
        raise ValueError(f"values must be a table of axes, got {axes!r}")
    if not axes:
        if samples is not None:
            raise ValueError("samples given, but no axes")
        return {}, []
    keys = list(axes)
    if kind == "grid":
        if samples is not None:
            raise ValueError("samples is for random and lhs axes; a grid has every combination")
        values = {key: _grid_values(key, axes[key]) for key in keys}
        count = math.prod(len(v) for v in values.values())
        if count > MAX_POINTS:
            raise ValueError(f"the grid has {count} points ({' x '.join(str(len(v)) for v in values.values())}); "
                             f"a study may have at most {MAX_POINTS}")
        return values, [dict(zip(keys, combo)) for combo in itertools.product(*values.values())]
    if isinstance(samples, bool) or not isinstance(samples, int) or not 1 <= samples <= MAX_POINTS:
        raise ValueError(f"samples must be a whole number in [1, {MAX_POINTS}] for {kind} axes, "
                         f"got {samples!r}")
    if kind == "random":
        unit = np.random.default_rng(seed).random((samples, len(keys)))
    else:
        unit = qmc.LatinHypercube(d=len(keys), rng=seed).random(samples)
    values = {key: _scale(key, axes[key], unit[:, i]) for i, key in enumerate(keys)}
    return values, [{key: values[key][i] for key in keys} for i in range(samples)]


def _load_report(path):
    try:
        report = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ValueError(f"report {path} not found; make it with: sma-fmu fit constant-load "
                         f"MEASUREMENTS.csv --out {path.parent}") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as error:
        raise ValueError(f"report {path}: not valid JSON: {error}") from None
    covariance = report.get("covariance") if isinstance(report, dict) else None
    if not isinstance(covariance, dict) or "parameters" not in covariance:
        raise ValueError(f"report {path} has no covariance (key 'covariance'); it needs the "
                         f"report.json of sma-fmu fit of this version")
    return report, covariance


def monte_carlo_draws(path, samples, parameters, seed):
    """[{NAME: value}] x ``samples`` ~ N(estimates, covariance) of a fit report.

    ``parameters`` restricts the draw to some of the report's parameters (the marginal of
    those); None draws them all.
    """
    report, covariance = _load_report(path)
    names = list(covariance["parameters"])
    chosen = names if parameters is None else parameters
    if not isinstance(chosen, list) or not chosen or any(p not in names for p in chosen):
        raise ValueError(f"parameters must be a non-empty list of the report's parameters "
                         f"({', '.join(names)}), got {parameters!r}")
    index = [names.index(p) for p in chosen]
    try:
        matrix = np.array(covariance["matrix"], dtype=float)[np.ix_(index, index)]
        mean = np.array([float(report["parameters"][p]["value"]) for p in chosen])
    except (KeyError, TypeError, ValueError, IndexError) as error:
        raise ValueError(f"report {path}: malformed estimates or covariance ({error})") from None
    if not (np.all(np.isfinite(matrix)) and np.allclose(matrix, matrix.T, rtol=1e-9, atol=0)):
        raise ValueError(f"report {path}: the covariance matrix is not finite and symmetric")
    rng = np.random.default_rng(seed + 1)
    draws = rng.multivariate_normal(mean, matrix, size=samples, method="cholesky"
                                    if np.all(np.linalg.eigvalsh(matrix) > 0) else "svd")
    return [{name: float(value) for name, value in zip(chosen, row)} for row in draws]
