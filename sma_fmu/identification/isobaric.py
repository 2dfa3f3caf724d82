"""Identify the constant-load model (spec sections 2-4) from isobaric thermal cycling.

The data: strain eps (and, where a file has it, resistance R) against a noisy temperature,
several heating and cooling branches per file, one load per file. The model of every
sample i of a file at load f, on the branch of its direction d:

    eps_i = eps_hot(f) + span(f) q(T_i; tau_d(f), dH(f)) + offset_i             [1]
    R_i   = R_hot(f)   + R_span(f) q(T_i; tau_d(f), dH(f))                       [ohm]

(:mod:`sma_fmu.identification.isobaric_model`). Fitted:
- the hysteresis centres: a_h, a_c at one load (b_h, b_c from the base file), or
  a_h, b_h, a_c, b_c when the files hold two loads or more;
- nu, the domain size that sets the transition width (eps_T from the base file: only
  nu eps_T is identifiable, as for the constant-load fit);
- l_MF = (l_M + l_F)/2 [m], the cold phase length, with l_F - l_M kept from the base file
  (the M/F split is invisible at constant load); x_min = l_P too when a file gives absolute
  lengths (a length column); with strain columns the zero of the strain is the file's own and
  x_min stays;
- R_P and R_MF = (R_M + R_F)/2 (R_F - R_M kept) when a file has resistance;
- strain offsets per file: one per residual-strain level with ``residual="per-cycle"``
  (heating branch k sits on level k; the cooling branch after it moves from level k to
  k + 1 in proportion to the transformed share q, so the cycle leaves level(k+1) -
  level(k) behind), or one per file with ``residual="none"``.

Errors in the temperature: the thermocouple noise (several kelvin) is far larger than what
the strain resolves on the steep part of a branch, so ordinary least squares against the
measured temperature would smear the transition (nu biased low) and give standard errors
that ignore the temperature noise. Instead the wire's temperature is a nuisance profile,
piecewise linear in time (in the sample index without a time column) with knots at the
turning points and about every twentieth of a branch, fitted together with the parameters:
the residuals are (profile - measured temperature)/sigma_T, (model strain at the profile -
measured strain)/sigma_eps and likewise for resistance, with each sigma estimated from the
data's own scatter (median absolute second difference). The covariance s^2 (J^T J)^-1 of
all unknowns then accounts for the temperature noise; the parameters' block is reported.
scipy's least_squares (trf, exact trust-region steps) gets the Jacobian in closed form
(derivatives of the logistic through tau, dH and the profile), so the profile's unknowns
cost no extra model evaluations.
"""
import math
import time
from dataclasses import dataclass

import numpy as np
from scipy import optimize, sparse

from sma_fmu.identification.isobaric_files import noise_level
from sma_fmu.identification.isobaric_jacobian import jacobian_rows
from sma_fmu.identification.isobaric_model import branch_levels, branch_share
from sma_fmu.identification.measurements import MeasurementError
from sma_fmu.runtime.constant_load import residual_f_fraction
from sma_fmu.runtime.constants import BOLTZMANN, COOLING, HEATING, KELVIN_OFFSET, STANDARD_GRAVITY

__all__ = ["RESIDUAL_OPTIONS", "IsobaricFit", "fit_isobaric", "file_model", "KNOTS_PER_BRANCH"]

RESIDUAL_OPTIONS = ("per-cycle", "none")
KNOTS_PER_BRANCH = 10
_FLOOR = 1e-9   # relative floor of the noise estimates (noise-free data)


@dataclass
class IsobaricFit:
    """Outcome of :func:`fit_isobaric`."""

    params: object            # WireParameters with the fitted values
    names: list               # the unknowns reported (physical and offsets)
    values: np.ndarray
    std_errors: np.ndarray
    covariance: np.ndarray    # of ``names``
    starts: np.ndarray
    wire_names: list          # parameter-file names the unknowns map to
    wire_values: np.ndarray
    wire_std_errors: np.ndarray
    wire_covariance: np.ndarray
    offsets: list             # per file: strain offset of each level [1]
    profiles: list            # per file: fitted wire temperature [degC] at each sample
    sigma: list               # per file: {"temperature", "strain", "resistance"} noise estimates
    residual_rms: dict        # {"temperature_K", "strain", "resistance_ohm"} of the fit
    variance_factor: float    # s^2: 1 when the noise estimates describe the residuals
    dof: int
    profile_unknowns: int
    evaluations: int
    converged: bool
    message: str
    seconds: float


def _knots(data):
    """Sample positions of the profile's knots: turning points and ~20 per branch."""
    knots = set()
    for b in data.branches:
        count = max(2, KNOTS_PER_BRANCH * (b.stop - b.start) // max(1, np.median(
            [c.stop - c.start for c in data.branches])))
        knots.update(np.linspace(b.start, b.stop - 1, int(count) + 1).round().astype(int).tolist())
    knots.update((0, data.temperature.size - 1))
    return np.array(sorted(knots))


def _basis(data):
    """Sparse (samples x knots) matrix of linear interpolation in time between the knots."""
    axis = data.time if data.time is not None else np.arange(data.temperature.size, dtype=float)
    knots = _knots(data)
    at = axis[knots]
    k = np.clip(np.searchsorted(at, axis, side="right") - 1, 0, at.size - 2)
    w = (axis - at[k]) / (at[k + 1] - at[k])
    rows = np.arange(axis.size)
    return sparse.csr_matrix((np.concatenate([1 - w, w]), (np.concatenate([rows, rows]),
                                                           np.concatenate([k, k + 1]))),
                             shape=(axis.size, at.size))


class _Layout:
    """Where each unknown lives in the vector, and how it maps onto the wire parameters."""

    def __init__(self, files, base, residual, fit_slopes, absolute, with_resistance):
        self.phys = ["a_h"] + (["b_h"] if fit_slopes else []) + ["a_c"] + \
            (["b_c"] if fit_slopes else []) + ["nu", "l_MF"] + (["x_min"] if absolute else []) + \
            (["R_P", "R_MF"] if with_resistance else [])
        self.offsets = []   # per file: (first column, count, level-0 fixed at zero)
        names = list(self.phys)
        for index, data in enumerate(files):
            count = data.levels if residual == "per-cycle" else 1
            fixed = data.absolute
            self.offsets.append((len(names), count - fixed, fixed))
            names += [f"offset_{index}_{level}" for level in range(fixed, count)]
        self.reported = names
        self.profiles = []
        column = len(names)
        for basis in files:
            self.profiles.append(column)
            column += basis.knot_count
        self.size = column
        self.base = base
        self.half_l = 0.5 * (base.l_F - base.l_M)
        self.half_r = 0.5 * (base.R_F - base.R_M)

    def params(self, vector):
        values = dict(zip(self.phys, vector[:len(self.phys)].tolist()))
        changes = {k: v for k, v in values.items() if k not in ("l_MF", "R_MF")}
        changes["l_M"], changes["l_F"] = values["l_MF"] - self.half_l, values["l_MF"] + self.half_l
        if "R_MF" in values:
            changes["R_M"] = values["R_MF"] - self.half_r
            changes["R_F"] = values["R_MF"] + self.half_r
        return self.base.replace(**changes)

    def levels(self, vector, index):
        first, count, fixed = self.offsets[index]
        return np.concatenate([[0.0] * fixed, vector[first:first + count]])


def _prepared(data, residual):
    """Per file: basis, knot count, row groups by direction, level of each row."""
    basis = _basis(data)
    level = np.zeros(data.temperature.size, dtype=int)
    direction = np.zeros(data.temperature.size, dtype=int)
    for b in data.branches:
        level[b.start:b.stop] = b.level if residual == "per-cycle" else 0
        direction[b.start:b.stop] = b.direction
    data.basis, data.knot_count = basis, basis.shape[1]
    data.row_level, data.row_direction = level, direction
    data.per_cycle = residual == "per-cycle"
    return data


def _sigmas(data):
    def floor(values, estimate):
        return max(estimate, _FLOOR * max(float(np.ptp(values)), 1.0))
    out = {"temperature": floor(data.temperature, noise_level(data.temperature)),
           "strain": max(noise_level(data.strain), _FLOOR * max(float(np.ptp(data.strain)), 1e-3))}
    if data.resistance is not None:
        out["resistance"] = floor(data.resistance, noise_level(data.resistance))
    return out


def file_model(params, data, profile, levels):
    """(strain, resistance or None) of the model at the profile temperatures."""
    strain = np.empty(profile.size)
    resistance = np.empty(profile.size) if data.resistance is not None else None
    for d in (HEATING, COOLING):
        rows = data.row_direction == d
        if not rows.any():
            continue
        lv = branch_levels(data.load, d, params, data.reference_length)
        q = branch_share(profile[rows], lv.constants)
        level = data.row_level[rows]
        offset = levels[level]
        if d == COOLING and data.per_cycle:
            offset = offset + (levels[np.minimum(level + 1, levels.size - 1)] - offset) * q
        strain[rows] = lv.strain_hot + lv.strain_span * q + offset
        if resistance is not None:
            resistance[rows] = lv.resistance_hot + lv.resistance_span * q
    return strain, resistance


def _crossings(data, profile):
    """Median temperature [degC] half way through each complete branch, and 25-75 % widths."""
    out = {HEATING: [], COOLING: []}
    for b in data.branches:
        if not b.complete:
            continue
        t, e = profile[b.start:b.stop], data.strain[b.start:b.stop]
        order = np.argsort(t)
        t, e = t[order], e[order]
        ends = max(3, t.size // 10)
        cold, hot = np.median(e[:ends]), np.median(e[-ends:])
        share = (e - hot) / (cold - hot)
        marks = []
        for target in (0.75, 0.5, 0.25):
            near = np.abs(share - target) <= 0.1
            marks.append(float(np.median(t[near])) if near.any() else math.nan)
        out[b.direction].append((marks[1], abs(marks[2] - marks[0]), cold - hot, cold, hot))
    return out


def _starts(files, layout, base):
    """Starting vector and bounds, estimated from the data."""
    vector = np.zeros(layout.size)
    profiles = []
    for data, column in zip(files, layout.profiles):
        basis = data.basis
        normal = (basis.T @ basis).toarray()
        profile_start = np.linalg.solve(normal, basis.T @ data.temperature)
        vector[column:column + data.knot_count] = profile_start
        profiles.append(basis @ profile_start)
    centres = {HEATING: [], COOLING: []}
    widths, spans, r_levels = [], [], []
    for data, profile in zip(files, profiles):
        marks = _crossings(data, profile)
        for d in (HEATING, COOLING):
            for centre, width, span, cold, hot in marks[d]:
                if math.isfinite(centre):
                    centres[d].append((data.load, centre))
                if math.isfinite(width) and width > 0:
                    widths.append((centre + KELVIN_OFFSET, width, data.load))
                spans.append((data, span, cold, hot))
        if data.resistance is not None:
            t = profile
            low, high = np.quantile(t, [0.1, 0.9])
            r_levels.append((data, float(np.median(data.resistance[t >= high])),
                             float(np.median(data.resistance[t <= low]))))
    for d in (HEATING, COOLING):
        if not centres[d]:
            raise MeasurementError(f"{', '.join(str(f.path) for f in files)}: no complete "
                                   f"{'heating' if d == HEATING else 'cooling'} branch crosses "
                                   f"the transformation")
    start = {}
    for d, a, b in ((HEATING, "a_h", "b_h"), (COOLING, "a_c", "b_c")):
        f, tau = np.array(centres[d]).T
        if b in layout.phys:
            slope, intercept = np.polyfit(f, tau, 1)
            start[a], start[b] = float(intercept), float(slope)
        else:
            start[a] = float(np.mean(tau - getattr(base, b) * f))
    # the 25-75 % width of the logistic is 2 ln 3 k_B T^2 / dH
    energy = np.median([2.0 * math.log(3.0) * BOLTZMANN * t * t / w for t, w, _ in widths])
    load = float(np.median([f for _, _, f in widths]))
    per_nu = base.eps_T - STANDARD_GRAVITY * load * base.x_T / base.N
    start["nu"] = float(energy / per_nu)
    span = float(np.median([s for _, s, _, _ in spans]))
    if not span > 0:
        raise MeasurementError(f"{files[0].path}: the strain is lower when cold than when hot; the "
                               f"model needs the wire to contract on heating (actuation strain > 0)")
    data0 = spans[0][0]
    xi_f_min = residual_f_fraction(data0.load, base)
    reference = data0.reference_length
    if "x_min" in layout.phys:
        cold_length = reference * (1 + float(np.median([c for _, _, c, _ in spans])))
        hot_length = reference * (1 + float(np.median([h for _, _, _, h in spans])))
        start["l_MF"] = cold_length - xi_f_min * layout.half_l
        start["x_min"] = (hot_length - xi_f_min * (start["l_MF"] + layout.half_l)) / (1 - xi_f_min)
    else:
        start["l_MF"] = base.x_min + span * reference / (1.0 - xi_f_min)
    if r_levels:
        data, r_hot, r_cold = r_levels[0]
        xi = residual_f_fraction(data.load, base)
        start["R_MF"] = r_cold - xi * layout.half_r
        start["R_P"] = (r_hot - xi * (start["R_MF"] + layout.half_r)) / (1.0 - xi)
    lower = np.full(layout.size, -np.inf)
    upper = np.full(layout.size, np.inf)
    x_min = start.get("x_min", base.x_min)
    bounds = {"a_h": (-100.0, 400.0), "a_c": (-100.0, 400.0), "b_h": (-5000.0, 5000.0),
              "b_c": (-5000.0, 5000.0), "nu": (1e-3 * start["nu"], 1e3 * start["nu"]),
              "l_MF": (x_min * (1 + 1e-9), 2.0 * x_min), "x_min": (0.5 * x_min, 2.0 * x_min),
              "R_P": (1e-3, start.get("R_MF", 1.0)), "R_MF": (start.get("R_P", 1.0), 1e4)}
    for i, name in enumerate(layout.phys):
        vector[i] = start[name]
        lower[i], upper[i] = bounds[name]
    vector[:len(layout.phys)] = np.clip(vector[:len(layout.phys)], lower[:len(layout.phys)] + 1e-12,
                                        upper[:len(layout.phys)] - 1e-12)
    params = layout.params(vector)
    for index, (data, profile) in enumerate(zip(files, profiles)):
        first, count, fixed = layout.offsets[index]
        strain, _ = file_model(params, data, profile, np.zeros(count + fixed))
        difference = data.strain - strain
        for level in range(fixed, count + fixed):
            rows = data.row_level == level
            vector[first + level - fixed] = float(np.median(difference[rows])) if rows.any() else 0.0
    for column, data in zip(layout.profiles, files):
        lower[column:column + data.knot_count] = -KELVIN_OFFSET + 1.0
    return vector, lower, upper


def fit_isobaric(files, base, residual="per-cycle", max_evaluations=200):
    """Fit the isobaric files (list of IsobaricData) jointly; returns :class:`IsobaricFit`."""
    if residual not in RESIDUAL_OPTIONS:
        raise ValueError(f"residual must be one of {', '.join(RESIDUAL_OPTIONS)}, got {residual!r}")
    files = [_prepared(data, residual) for data in files]
    loads = sorted({data.load for data in files})
    layout = _Layout(files, base, residual, len(loads) >= 2, any(d.absolute for d in files),
                     any(d.resistance is not None for d in files))
    sigma = [_sigmas(data) for data in files]
    vector, lower, upper = _starts(files, layout, base)
    starts = vector[:len(layout.reported)].copy()

    def pieces(x):
        params = layout.params(x)
        out = []
        for index, (data, column, s) in enumerate(zip(files, layout.profiles, sigma)):
            profile = data.basis @ x[column:column + data.knot_count]
            strain, resistance = file_model(params, data, profile, layout.levels(x, index))
            out.append((profile - data.temperature) / s["temperature"])
            out.append((strain - data.strain) / s["strain"])
            if resistance is not None:
                out.append((resistance - data.resistance) / s["resistance"])
        return out

    def residuals(x):
        return np.concatenate(pieces(x))

    def jacobian(x):
        return np.vstack([block for index, (data, column, s) in
                          enumerate(zip(files, layout.profiles, sigma))
                          for block in jacobian_rows(x, layout, data, index, column, s)])

    began = time.perf_counter()
    solution = optimize.least_squares(
        residuals, vector, jac=jacobian, bounds=(lower, upper), method="trf", x_scale="jac",
        tr_solver="exact", xtol=1e-12, ftol=1e-12, gtol=1e-10, max_nfev=max_evaluations)
    seconds = time.perf_counter() - began
    jac = solution.jac
    m, n = solution.fun.size, layout.size
    dof = max(m - n, 1)
    factor = float(np.sum(solution.fun ** 2)) / dof
    normal = jac.T @ jac
    scale = np.sqrt(np.clip(np.diag(normal), 1e-300, None))
    covariance = factor * np.linalg.pinv(normal / np.outer(scale, scale)) / np.outer(scale, scale)
    k = len(layout.reported)
    cov = covariance[:k, :k]
    params = layout.params(solution.x)
    wire_names, wire_values, wire_cov = _wire_covariance(layout, solution.x, cov)
    rms = {"temperature_K": [], "strain": [], "resistance_ohm": []}
    parts = pieces(solution.x)
    i = 0
    for data, s in zip(files, sigma):
        rms["temperature_K"].append(parts[i] * s["temperature"])
        rms["strain"].append(parts[i + 1] * s["strain"])
        i += 2
        if data.resistance is not None:
            rms["resistance_ohm"].append(parts[i] * s["resistance"])
            i += 1
    rms = {key: float(np.sqrt(np.mean(np.concatenate(v) ** 2))) if v else None
           for key, v in rms.items()}
    return IsobaricFit(
        params=params, names=list(layout.reported), values=solution.x[:k].copy(),
        std_errors=np.sqrt(np.clip(np.diag(cov), 0, None)), covariance=cov, starts=starts,
        wire_names=wire_names, wire_values=wire_values,
        wire_std_errors=np.sqrt(np.clip(np.diag(wire_cov), 0, None)), wire_covariance=wire_cov,
        offsets=[layout.levels(solution.x, i).tolist() for i in range(len(files))],
        profiles=[data.basis @ solution.x[c:c + data.knot_count]
                  for data, c in zip(files, layout.profiles)],
        sigma=sigma, residual_rms=rms, variance_factor=factor, dof=dof,
        profile_unknowns=n - k, evaluations=int(solution.nfev),
        converged=bool(solution.status > 0), message=str(solution.message), seconds=seconds)


def _wire_covariance(layout, vector, cov):
    """Names, values and covariance of the parameter-file entries the unknowns set."""
    names, rows = [], []
    for i, name in enumerate(layout.phys):
        for target in {"l_MF": ("l_M", "l_F"), "R_MF": ("R_M", "R_F")}.get(name, (name,)):
            row = np.zeros(cov.shape[0])
            row[i] = 1.0
            names.append(target)
            rows.append(row)
    transform = np.array(rows)
    params = layout.params(vector)
    values = np.array([getattr(params, name) for name in names])
    return names, values, transform @ cov @ transform.T
