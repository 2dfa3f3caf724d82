"""Identify the constant-load model (spec sections 2-4) from isobaric thermal cycling.

The data: strain eps (and, where a file has it, resistance R) against a noisy thermocouple
temperature, from two to a thousand heating and cooling branches per file, one load per
file. The model of every sample i of a file at load f, on the branch of its direction d:

    eps_i = eps_hot(f) + span(f) q(T_i; tau_d(f), dH(f)) + offset_i             [1]
    R_i   = R_hot(f)   + R_span(f) q(T_i; tau_d(f), dH(f))                       [ohm]

(:mod:`sma_fmu.identification.isobaric.model`). Fitted:
- the hysteresis centres: a_h, a_c at one load (b_h, b_c from the base file), or
  a_h, b_h, a_c, b_c when the files hold two loads or more;
- nu, the domain size that sets the transition width (eps_T from the base file: only
  nu eps_T is identifiable, as for the constant-load fit);
- l_MF = (l_M + l_F)/2 [m] (l_F - l_M kept from the base file), x_min too when a file gives
  absolute lengths; R_P and R_MF when a file has resistance;
- strain offsets per file: one per residual-strain level with ``residual="per-cycle"``
  (heating branch k sits on level k; the cooling branch after it moves from level k to
  k + 1 in proportion to the transformed share q), or one per file with ``residual="none"``;
- the lag of the wire behind the thermocouple, one time constant per file [s, or samples
  when the file has no time column] (``lag="fit"``; ``lag="none"`` holds it at zero).

The wire temperature T_i is lagged(profile): the profile is piecewise linear with few knots
per branch, chosen from the measured temperature alone (:mod:`profile`), and its
knots are fitted jointly with the parameters against the residuals (profile - measured
temperature)/sigma_T, (model strain - measured strain)/sigma_eps (and resistance), each sigma
the data's own scatter (median absolute second difference). So the profile can move only
as far as the thermocouple noise allows: a wire that lags is explained by the lag, and a
temperature residual much larger than the noise says the model does not explain the data
(``verdict``). The covariance s^2 (J^T J)^-1 of all unknowns accounts for the temperature
noise. Levenberg-Marquardt with sparse direct steps (:mod:`solver`) runs on a sparse
closed-form Jacobian (:mod:`jacobian`), so a 26,000-sample, 100-cycle file fits in
seconds; a short scan of starting lags picks the valley first.
"""
import time
from dataclasses import dataclass

import numpy as np
from scipy import sparse
from threadpoolctl import threadpool_limits

from sma_fmu.identification.isobaric.files import noise_level
from sma_fmu.identification.isobaric.jacobian import file_jacobian, file_model, file_state
from sma_fmu.identification.isobaric.lag import uniform_step
from sma_fmu.identification.isobaric.layout import Layout, starts
from sma_fmu.identification.isobaric.profile import temperature_profile
from sma_fmu.identification.isobaric.solver import OrderedLU, levenberg_marquardt
from sma_fmu.identification.measurements import MeasurementError

__all__ = ["RESIDUAL_OPTIONS", "LAG_OPTIONS", "IsobaricFit", "fit_isobaric", "prepare",
           "residual_blocks",
           "EXPLAINED_RATIO"]

RESIDUAL_OPTIONS = ("per-cycle", "none")
LAG_OPTIONS = ("fit", "none")
EXPLAINED_RATIO = 1.5   # residual RMS above this many noise estimates: not explained
_FLOOR = 1e-9           # relative floor of the noise estimates (noise-free data)
_PROGRESS_S = 5.0       # seconds between progress lines
SCAN_EVALUATIONS = 6    # per starting lag before the full fit
LAG_STARTS = (1 / 300, 1 / 100, 1 / 50, 1 / 25, 1 / 12, 1 / 6)   # of a cycle


@dataclass
class PreparedFile:
    """One file with its temperature profile, sample step and noise estimates."""

    index: int
    data: object
    profile: object
    step: float             # s, or 1 (sample) without a time column
    step_spread: float      # largest relative deviation of a time step from the median
    sigma: dict             # noise estimates: temperature [K], strain [1], resistance [ohm]
    per_cycle: bool

    @property
    def lag_unit(self):
        return "s" if self.data.time is not None else "samples"


@dataclass
class IsobaricFit:
    """Outcome of :func:`fit_isobaric`."""

    params: object            # WireParameters with the fitted values
    names: list               # the unknowns reported (physical, offsets, lags)
    values: np.ndarray
    std_errors: np.ndarray
    covariance: np.ndarray    # of ``names``
    starts: np.ndarray
    wire_names: list          # parameter-file names the unknowns map to
    wire_values: np.ndarray
    wire_std_errors: np.ndarray
    wire_covariance: np.ndarray
    offsets: list             # per file: strain offset of each level [1]
    lags: list                # per file: {"value", "std_error", "unit", "step", "step_spread"}
    profiles: list            # per file: fitted wire temperature [degC] at each sample
    measured_profiles: list   # per file: fitted thermocouple temperature (before the lag)
    directions: list          # per file: the wire's branch direction (+1/-1) at each sample
    row_levels: list          # per file: the residual-strain level of each sample
    wire_bounds: list         # per file: first row of each wire branch, then the end
    sigma: list               # per file: {"temperature", "strain", "resistance"} noise estimates
    residual_rms: dict        # {"temperature_K", "strain", "resistance_ohm"} of the fit
    noise: dict               # the same keys: the noise estimates (RMS over the files)
    verdict: str              # one line: explained or not, and why
    variance_factor: float    # s^2: 1 when the noise estimates describe the residuals
    dof: int
    profile_unknowns: int
    knots_per_branch: list
    evaluations: int
    converged: bool
    message: str
    seconds: float


def prepare(data, index, residual="per-cycle"):
    """:class:`PreparedFile` of one IsobaricData: profile knots, step, noise estimates."""
    def floor(values, estimate, least=1.0):
        return max(estimate, _FLOOR * max(float(np.ptp(values)), least))
    window = data.splitting.window_samples if data.splitting is not None else 5
    sigma = {"temperature": floor(data.temperature, noise_level(data.temperature)),
             "strain": floor(data.strain, noise_level(data.strain), 1e-3)}
    if data.resistance is not None:
        sigma["resistance"] = floor(data.resistance, noise_level(data.resistance))
    step, spread = uniform_step(data.time)
    profile = temperature_profile(data.temperature, data.branches, data.time, window)
    return PreparedFile(index, data, profile, step, spread, sigma, residual == "per-cycle")


def _verdict(rms, noise):
    """One line: whether the residuals are what the noise estimates predict."""
    ratios = {key: rms[key] / noise[key] for key in rms if rms[key] is not None and noise[key]}
    unit = {"temperature_K": " K", "strain": "", "resistance_ohm": " ohm"}
    worst = [f"{key.split('_')[0]} residual {rms[key]:.3g}{unit[key]} is {ratio:.1f}x its noise "
             f"estimate {noise[key]:.3g}{unit[key]}" for key, ratio in ratios.items()
             if ratio > EXPLAINED_RATIO]
    if worst:
        return "the model does not explain the data: " + "; ".join(worst) + \
            (" (the wire temperature had to move beyond the thermocouple noise)"
             if ratios.get("temperature_K", 0) > EXPLAINED_RATIO else "")
    return ("the model explains the data within the noise: residuals "
            + ", ".join(f"{key.split('_')[0]} {ratio:.2f}x" for key, ratio in ratios.items())
            + " their noise estimates")


def _lag_scan(start, solve, progress):
    """The two best of short fits started from lags of 1/300 to 1/6 of a cycle, each with the
    centres read on the profile lagged by it (the lag trades against the centres, and the
    cost surface can have more than one valley; the full fit runs from both)."""
    trials = []
    for fraction in LAG_STARTS:
        trial = solve(start(fraction), SCAN_EVALUATIONS)
        if progress is not None:
            progress(f"  lag start {fraction:.3g} of a cycle: cost {trial.cost:.6g} after "
                     f"{trial.nfev} evaluations")
        trials.append(trial)
    trials.sort(key=lambda trial: trial.cost)
    return [trial.x for trial in trials[:2]]


def _reported_covariance(jac, factor, count, order):
    """s^2 (J^T J)^-1 restricted to the first ``count`` unknowns (sparse LU of the scaled
    normal matrix; a tiny ridge keeps unvisited levels from making it singular)."""
    normal = (jac.T @ jac).tocsc()
    scale = np.sqrt(np.clip(normal.diagonal(), 1e-300, None))
    scaled = sparse.diags(1 / scale) @ normal @ sparse.diags(1 / scale)
    scaled = scaled + 1e-12 * sparse.identity(scaled.shape[0])
    unit = np.zeros((scaled.shape[0], count))
    unit[np.arange(count), np.arange(count)] = 1.0
    inverse = OrderedLU(scaled, order).solve(unit)[:count]
    return factor * inverse / np.outer(scale[:count], scale[:count])


def residual_blocks(x, layout, prepared):
    """Weighted residuals of every file: [temperature, strain(, resistance)] per file."""
    params = layout.params(x)
    out = []
    for f in prepared:
        profile, _, wire, direction, level, _ = file_state(x, layout, f)
        strain, resistance = file_model(params, f.data, wire, layout.levels(x, f.index),
                                        direction, level, f.per_cycle)
        out.append((profile - f.data.temperature) / f.sigma["temperature"])
        out.append((strain - f.data.strain) / f.sigma["strain"])
        if resistance is not None:
            out.append((resistance - f.data.resistance) / f.sigma["resistance"])
    return out


def fit_isobaric(files, base, residual="per-cycle", lag="fit", max_evaluations=300,
                 progress=None):
    """Fit the isobaric files (list of IsobaricData) jointly; returns :class:`IsobaricFit`.

    ``progress`` (callable taking a line of text, or None) hears from long fits.
    """
    if residual not in RESIDUAL_OPTIONS:
        raise ValueError(f"residual must be one of {', '.join(RESIDUAL_OPTIONS)}, got {residual!r}")
    if lag not in LAG_OPTIONS:
        raise ValueError(f"lag must be one of {', '.join(LAG_OPTIONS)}, got {lag!r}")
    prepared = [prepare(data, index, residual) for index, data in enumerate(files)]
    loads = sorted({data.load for data in files})
    layout = Layout(prepared, base, len(loads) >= 2, any(d.absolute for d in files),
                    any(d.resistance is not None for d in files), lag == "fit")
    vector, lower, upper = starts(prepared, layout, base)
    order = layout.time_order(prepared)
    first = vector[:len(layout.reported)].copy()
    began = time.perf_counter()
    clock = {"last": began, "evaluations": 0}

    def pieces(x):
        return residual_blocks(x, layout, prepared)

    def residuals(x):
        out = np.concatenate(pieces(x))
        clock["evaluations"] += 1
        now = time.perf_counter()
        if progress is not None and now - clock["last"] > _PROGRESS_S:
            clock["last"] = now
            progress(f"  fit: {clock['evaluations']} evaluations, cost {0.5 * out @ out:.6g}, "
                     f"{now - began:.0f} s")
        return out

    def jacobian(x):
        return sparse.vstack([b for f in prepared for b in file_jacobian(x, layout, f)]).tocsr()

    def solve(x0, evaluations):
        return levenberg_marquardt(residuals, jacobian, x0, lower, upper, evaluations, ftol=1e-8,
                                   order=order)

    # the sparse solves gain nothing from BLAS threads, which only contend for the cores
    with threadpool_limits(limits=1, user_api="blas"):
        firsts = [vector] if lag != "fit" else _lag_scan(
            lambda fraction: starts(prepared, layout, base, fraction)[0], solve, progress)
        solution = min((solve(x, max_evaluations) for x in firsts), key=lambda s: s.cost)
    if not np.all(np.isfinite(solution.x)):
        layout.params(np.where(np.isfinite(solution.x), solution.x, np.nan))
    seconds = time.perf_counter() - began
    jac = jacobian(solution.x)
    m, n = solution.fun.size, layout.size
    dof = max(m - n, 1)
    factor = float(np.sum(solution.fun ** 2)) / dof
    k = len(layout.reported)
    cov = _reported_covariance(jac, factor, k, order)
    if not np.all(np.isfinite(cov)):
        raise MeasurementError(f"{layout.paths}: the fit's covariance is not finite; the data do "
                               f"not determine the unknowns")
    params = layout.params(solution.x)
    errors = np.sqrt(np.clip(np.diag(cov), 0, None))
    parts, states = pieces(solution.x), [file_state(solution.x, layout, f) for f in prepared]
    rms, noise = {"temperature_K": [], "strain": [], "resistance_ohm": []}, \
        {"temperature_K": [], "strain": [], "resistance_ohm": []}
    i = 0
    for f in prepared:
        for key, sigma_key in (("temperature_K", "temperature"), ("strain", "strain"),
                               ("resistance_ohm", "resistance")):
            if sigma_key in f.sigma:
                rms[key].append(parts[i] * f.sigma[sigma_key])
                noise[key].append(np.full(parts[i].size, f.sigma[sigma_key]))
                i += 1
    rms = {key: float(np.sqrt(np.mean(np.concatenate(v) ** 2))) if v else None
           for key, v in rms.items()}
    noise = {key: float(np.sqrt(np.mean(np.concatenate(v) ** 2))) if v else None
             for key, v in noise.items()}
    wire_names, wire_values, wire_cov = _wire_covariance(layout, solution.x, cov)
    lags = [None if c is None else {"value": float(solution.x[c]), "std_error": float(errors[c]),
                                    "unit": f.lag_unit, "step": f.step,
                                    "step_spread": f.step_spread}
            for f, c in zip(prepared, layout.lags)]
    return IsobaricFit(
        params=params, names=list(layout.reported), values=solution.x[:k].copy(),
        std_errors=errors, covariance=cov, starts=first,
        wire_names=wire_names, wire_values=wire_values,
        wire_std_errors=np.sqrt(np.clip(np.diag(wire_cov), 0, None)), wire_covariance=wire_cov,
        offsets=[layout.levels(solution.x, f.index).tolist() for f in prepared], lags=lags,
        profiles=[s[2] for s in states], measured_profiles=[s[0] for s in states],
        directions=[s[3] for s in states], row_levels=[s[4] for s in states], wire_bounds=[s[5] for s in states],
        sigma=[f.sigma for f in prepared], residual_rms=rms, noise=noise,
        verdict=_verdict(rms, noise), variance_factor=factor, dof=dof, profile_unknowns=n - k,
        knots_per_branch=[f.profile.knots_per_branch for f in prepared],
        evaluations=int(clock["evaluations"]), converged=bool(solution.status > 0),
        message=str(solution.message), seconds=seconds)


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
