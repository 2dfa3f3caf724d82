"""Identify the constant-load model (spec sections 2-4, with the issue-36 terms) from
isobaric thermal cycling.

The data: strain eps (and, where a file has it, resistance R) against a noisy thermocouple
temperature, from one to a thousand heating and cooling branches per file, one load per
file. The model of every sample i of a file at load f, on the branch of its direction d,
is :func:`sma_fmu.identification.isobaric.terms.branch_curve` (two logistic stages, thermal
expansion, the stress law of the transformation strain) plus a strain offset. Fitted
(:mod:`~.layout` lists the unknowns, :mod:`~.starts` their starts and bounds):
- the hysteresis centres of each stage, held as the cooling line and the heating centre's
  lead over it (>= 0) at no load and at the largest load; slopes b with two loads or more;
- the domain sizes: one nu, or nu_h and nu_c (``widths``), and nu2_h, nu2_c, w2 with a
  second stage (``stages=2``); richer models are kept only when they lower the cost by
  STAGE_GAIN_MIN;
- alpha_P, alpha_MF; span_ratio_0 with two stresses or more, span_stress with three;
- l_MF = (l_M + l_F)/2 [m] (l_F - l_M kept from the base file), x_min too when a file gives
  absolute lengths; R_P and R_MF when a file has resistance;
- strain offsets per file: one per residual-strain level with ``residual="per-cycle"``
  (heating branch k sits on level k; the cooling branch after it moves from level k to
  k + 1 in proportion to the transformed share q), or one per file with ``residual="none"``;
- the lag of the wire behind the thermocouple, one time constant per file [s, or samples
  when the file has no time column] (``lag="fit"``, bounded by starts.LAG_LIMIT of a cycle;
  ``lag="none"`` holds it at zero).

Outlier cycles (:mod:`~.outliers`) are named and, by default, left out; unknowns that end on
a bound are named. The wire temperature T_i is lagged(profile): the profile is piecewise
linear with few knots per branch, chosen from the measured temperature alone
(:mod:`profile`), and its knots are fitted jointly with the parameters against the
residuals (profile - measured temperature)/sigma_T, (model strain - measured
strain)/sigma_eps (and resistance), each sigma the data's own scatter (median absolute
second difference). So the profile can move only as far as the thermocouple noise allows:
a wire that lags is explained by the lag, and a temperature residual much larger than the
noise says the model does not explain the data (``verdict``). The covariance
s^2 (J^T J)^-1 of all unknowns (:mod:`~.covariance`) accounts for the temperature noise.
Levenberg-Marquardt with sparse direct steps (:mod:`solver`) runs on a sparse Jacobian
(:mod:`jacobian`), so a 26,000-sample, 100-cycle file fits in seconds; a short scan of
starting lags picks the valley first.
"""
import time
from collections import namedtuple
from dataclasses import dataclass

import numpy as np
from scipy import sparse
from threadpoolctl import threadpool_limits

from sma_fmu.identification.isobaric.files import noise_level
from sma_fmu.identification.isobaric.jacobian import file_jacobian, file_model, file_state
from sma_fmu.identification.isobaric.lag import uniform_step
from sma_fmu.identification.isobaric.covariance import (named, named_values,
                                                        reported_covariance, wire_covariance)
from sma_fmu.identification.isobaric.centre_law import CENTRE_LAWS, SHARE_STRESSES, law_attempt
from sma_fmu.identification.isobaric.layout import Layout
from sma_fmu.identification.isobaric.outliers import OUTLIER_OPTIONS, bound_names, mark_outliers
from sma_fmu.identification.isobaric.starts import starts
from sma_fmu.identification.isobaric.profile import temperature_profile
from sma_fmu.identification.isobaric.solver import levenberg_marquardt
from sma_fmu.identification.measurements import MeasurementError
from sma_fmu.runtime.model_terms import domain_widths

__all__ = ["RESIDUAL_OPTIONS", "LAG_OPTIONS", "OUTLIER_OPTIONS", "IsobaricFit", "fit_isobaric", "prepare",
           "residual_blocks",
           "EXPLAINED_RATIO"]

RESIDUAL_OPTIONS = ("per-cycle", "none")
LAG_OPTIONS = ("fit", "none")
WIDTH_OPTIONS = ("auto", "separate", "shared")
STAGE_SHARE_MIN = 1e-3  # a second stage holding less than this share of M is not kept
STAGE_GAIN_MIN = 0.01   # nor one that lowers the cost by less than this fraction
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
    weight: np.ndarray = None   # per sample: 1, or 0 for the strain of a left-out cycle

    def __post_init__(self):
        if self.weight is None:
            self.weight = np.ones(self.data.strain.size)

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
    on_bound: list = None     # "name = value (lower/upper bound)" of unknowns on a bound
    outlier_cycles: list = None   # [{"file", "cycle", "rms", "name"}] left out of the fit
    stages: int = 1
    stage_note: str = ""      # why a second stage asked for was not kept
    undetermined: list = None  # unknowns no residual touches (levels of left-out cycles)
    file_rms: list = None     # per file: {"temperature_K", "strain"(, "resistance_ohm")} RMS


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


def residual_blocks(x, layout, prepared):
    """Weighted residuals of every file: [temperature, strain(, resistance)] per file."""
    params = layout.params(x)
    out = []
    for f in prepared:
        profile, _, wire, direction, level, _ = file_state(x, layout, f)
        strain, resistance = file_model(params, f.data, wire, layout.levels(x, f.index),
                                        direction, level, f.per_cycle)
        out.append((profile - f.data.temperature) / f.sigma["temperature"])
        out.append(f.weight * (strain - f.data.strain) / f.sigma["strain"])
        if resistance is not None:
            out.append(f.weight * (resistance - f.data.resistance) / f.sigma["resistance"])
    return out


def _solver(prepared, layout, lower, upper, progress, clock):
    """(residuals, jacobian, solve) of one layout."""
    order = layout.time_order(prepared)

    def residuals(x):
        out = np.concatenate(residual_blocks(x, layout, prepared))
        clock["evaluations"] += 1
        now = time.perf_counter()
        if progress is not None and now - clock["last"] > _PROGRESS_S:
            clock["last"] = now
            progress(f"  fit: {clock['evaluations']} evaluations, cost {0.5 * out @ out:.6g}, "
                     f"{now - clock['began']:.0f} s")
        return out

    def jacobian(x):
        return sparse.vstack([b for f in prepared for b in file_jacobian(x, layout, f)]).tocsr()

    def solve(x0, evaluations):
        return levenberg_marquardt(residuals, jacobian, x0, lower, upper, evaluations, ftol=1e-8,
                                   order=order)
    return residuals, jacobian, solve, order


_State = namedtuple("_State", ["layout", "solution", "jacobian", "solve", "order", "lower",
                               "upper", "first"])


def _carry(old_layout, old_x, layout, vector):
    """``vector`` with every unknown the two layouts share taken from ``old_x`` (one width
    nu gives both nu_h and nu_c: :func:`~sma_fmu.runtime.model_terms.domain_widths`)."""
    out = vector.copy()
    old = dict(zip(old_layout.phys, old_x))
    old.update(domain_widths(old))
    for i, name in enumerate(layout.phys):
        if name in old:
            out[i] = old[name]
    k_old, k = len(old_layout.phys), len(layout.phys)
    out[k:layout.size] = old_x[k_old:old_layout.size]
    return out


def fit_isobaric(files, base, residual="per-cycle", lag="fit", max_evaluations=300,
                 progress=None, stages=1, outliers="leave-out", widths="auto",
                 centre_law="linear"):
    """Fit the isobaric files (list of IsobaricData) jointly; returns :class:`IsobaricFit`.

    ``stages``: 1, or 2 (a second stage, fitted from the one-stage fit); ``widths``:
    "separate" (nu_h, nu_c), "shared" (one nu for both directions) or "auto" (shared, then
    separate kept only when it lowers the cost by STAGE_GAIN_MIN: with a fitted lag, separate
    widths blur the lag against the centres); ``outliers``:
    "leave-out" (cycles whose strain residual RMS exceeds OUTLIER_RATIO times the median
    cycle's are named and fitted again without their strain) or "keep"; ``centre_law``:
    "linear" or "clausius-clapeyron" (each direction's share of :mod:`~.centre_law`, fitted
    last, from the linear fit, with three stresses or more).
    ``progress`` (callable taking a line of text, or None) hears from long fits.
    """
    if residual not in RESIDUAL_OPTIONS:
        raise ValueError(f"residual must be one of {', '.join(RESIDUAL_OPTIONS)}, got {residual!r}")
    if lag not in LAG_OPTIONS:
        raise ValueError(f"lag must be one of {', '.join(LAG_OPTIONS)}, got {lag!r}")
    if widths not in WIDTH_OPTIONS:
        raise ValueError(f"widths must be one of {', '.join(WIDTH_OPTIONS)}, got {widths!r}")
    if stages not in (1, 2):
        raise ValueError(f"stages must be 1 or 2, got {stages!r}")
    if centre_law not in CENTRE_LAWS:
        raise ValueError(f"centre_law must be one of {', '.join(CENTRE_LAWS)}, got {centre_law!r}")
    if outliers not in OUTLIER_OPTIONS:
        raise ValueError(f"outliers must be one of {', '.join(OUTLIER_OPTIONS)}, got {outliers!r}")
    prepared = [prepare(data, index, residual) for index, data in enumerate(files)]
    loads = sorted({data.load for data in files})

    # the centre law's shares are fitted last, from the linear fit (centre_law.py)
    fit_law = centre_law == "clausius-clapeyron" and len(loads) >= SHARE_STRESSES
    law = "linear" if fit_law else centre_law

    def layout_of(count, kind):
        return Layout(prepared, base, len(loads) >= 2, any(d.absolute for d in files),
                      any(d.resistance is not None for d in files), lag == "fit", count, loads,
                      kind, law)
    began = time.perf_counter()
    clock = {"last": began, "evaluations": 0, "began": began}

    def attempt(state, count, kind):
        """A richer layout started from ``state``'s solution."""
        layout = layout_of(count, kind)
        vector, lower, upper = starts(prepared, layout, base)
        first = _carry(state.layout, state.first, layout, vector)
        vector = _carry(state.layout, state.solution.x, layout, vector)
        residuals, jacobian, solve, order = _solver(prepared, layout, lower, upper, progress,
                                                    clock)
        solution = solve(np.clip(vector, lower, upper), max_evaluations)
        return _State(layout, solution, jacobian, solve, order, lower, upper, first)

    kind = "separate" if widths == "separate" else "shared"
    layout = layout_of(1, kind)
    vector, lower, upper = starts(prepared, layout, base)
    residuals, jacobian, solve, order = _solver(prepared, layout, lower, upper, progress, clock)
    notes = []
    # the sparse solves gain nothing from BLAS threads, which only contend for the cores
    with threadpool_limits(limits=1, user_api="blas"):
        firsts = [vector] if lag != "fit" else _lag_scan(
            lambda fraction: starts(prepared, layout, base, fraction)[0], solve, progress)
        solution = min((solve(x, max_evaluations) for x in firsts), key=lambda s: s.cost)
        left_out = mark_outliers(prepared, layout, solution.x, outliers == "leave-out")
        if left_out and progress is not None:
            progress(f"  outlier cycles {'left out' if outliers == 'leave-out' else 'kept'}: "
                     + "; ".join(c["name"] for c in left_out))
        if left_out and outliers == "leave-out":
            solution = solve(solution.x, max_evaluations)
        state = _State(layout, solution, jacobian, solve, order, lower, upper, vector.copy())
        if widths == "auto":
            richer = attempt(state, 1, "separate")
            if richer.solution.cost <= (1.0 - STAGE_GAIN_MIN) * state.solution.cost:
                state, kind = richer, "separate"
            else:
                notes.append(f"separate heating and cooling widths do not fit these data better "
                             f"(cost {richer.solution.cost:.6g} against "
                             f"{state.solution.cost:.6g} with one): one width kept")
        if stages == 2:
            richer = attempt(state, 2, kind)
            w2 = richer.solution.x[richer.layout.phys.index("w2")]
            if w2 > STAGE_SHARE_MIN and \
                    richer.solution.cost <= (1.0 - STAGE_GAIN_MIN) * state.solution.cost:
                state = richer
            else:
                notes.append(f"a second stage does not fit these data better (w2 = {w2:.3g}, "
                             f"cost {richer.solution.cost:.6g} against "
                             f"{state.solution.cost:.6g} with one stage): one stage kept")
                stages = 1
        if fit_law:
            law = centre_law
            state, note = law_attempt(state, attempt(state, stages, kind), STAGE_GAIN_MIN)
            notes += [note] if note else []
    for note in notes if progress is not None else ():
        progress("  " + note)
    stage_note = "; ".join(notes)
    layout, solution, jacobian, solve, order, lower, upper, first = state
    first = first[:len(layout.reported)]
    if not np.all(np.isfinite(solution.x)):
        layout.params(np.where(np.isfinite(solution.x), solution.x, np.nan))
    seconds = time.perf_counter() - began
    jac = jacobian(solution.x)
    m, n = solution.fun.size, layout.size
    dof = max(m - n - sum(int(np.sum(f.weight == 0)) for f in prepared), 1)
    factor = float(np.sum(solution.fun ** 2)) / dof
    k = len(layout.reported)
    cov, dead = reported_covariance(jac, factor, k, order)
    names, to_names = named(layout, solution.x)
    on_bound = bound_names(layout, solution.x, lower, upper)
    if not np.all(np.isfinite(cov)):
        raise MeasurementError(f"{layout.paths}: the fit's covariance is not finite; the data do "
                               f"not determine the unknowns")
    params = layout.params(solution.x)
    cov[dead, :], cov[:, dead] = 0.0, 0.0    # undetermined: reported as a zero error, named
    undetermined = [layout.reported[i] for i in np.nonzero(dead)[0]]
    errors = np.sqrt(np.clip(np.diag(cov), 0, None))
    cov_named = to_names @ cov @ to_names.T
    values = named_values(layout, solution.x, names)
    parts, states = residual_blocks(solution.x, layout, prepared), \
        [file_state(solution.x, layout, f) for f in prepared]
    rms, noise = {"temperature_K": [], "strain": [], "resistance_ohm": []}, \
        {"temperature_K": [], "strain": [], "resistance_ohm": []}
    i, file_rms = 0, []
    for f in prepared:
        file_rms.append({})
        for key, sigma_key in (("temperature_K", "temperature"), ("strain", "strain"),
                               ("resistance_ohm", "resistance")):
            if sigma_key in f.sigma:
                kept = f.weight > 0 if sigma_key != "temperature" else slice(None)
                rms[key].append(parts[i][kept] * f.sigma[sigma_key])
                noise[key].append(np.full(parts[i][kept].size, f.sigma[sigma_key]))
                file_rms[-1][key] = float(np.sqrt(np.mean(rms[key][-1] ** 2)))
                i += 1
    rms = {key: float(np.sqrt(np.mean(np.concatenate(v) ** 2))) if v else None
           for key, v in rms.items()}
    noise = {key: float(np.sqrt(np.mean(np.concatenate(v) ** 2))) if v else None
             for key, v in noise.items()}
    wire_names, wire_values, wire_cov = wire_covariance(names, values, cov_named, layout)
    lags = [None if c is None else {"value": float(solution.x[c]), "std_error": float(errors[c]),
                                    "unit": f.lag_unit, "step": f.step,
                                    "step_spread": f.step_spread}
            for f, c in zip(prepared, layout.lags)]
    return IsobaricFit(
        params=params, names=names, values=values,
        std_errors=np.sqrt(np.clip(np.diag(cov_named), 0, None)), covariance=cov_named,
        starts=named_values(layout, first, names),
        wire_names=wire_names, wire_values=wire_values,
        wire_std_errors=np.sqrt(np.clip(np.diag(wire_cov), 0, None)), wire_covariance=wire_cov,
        offsets=[layout.levels(solution.x, f.index).tolist() for f in prepared], lags=lags,
        profiles=[s[2] for s in states], measured_profiles=[s[0] for s in states],
        directions=[s[3] for s in states], row_levels=[s[4] for s in states], wire_bounds=[s[5] for s in states],
        sigma=[f.sigma for f in prepared], residual_rms=rms, noise=noise,
        verdict=_verdict(rms, noise), variance_factor=factor, dof=dof, profile_unknowns=n - k,
        knots_per_branch=[f.profile.knots_per_branch for f in prepared],
        evaluations=int(clock["evaluations"]), converged=bool(solution.status > 0),
        message=str(solution.message), seconds=seconds, on_bound=on_bound,
        outlier_cycles=left_out, stages=stages, file_rms=file_rms, stage_note=stage_note,
        undetermined=undetermined)
