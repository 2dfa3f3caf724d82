"""Identify the constant-load model (spec sections 2-4, with the issue-36 terms) from
isobaric thermal cycling.

The data: strain eps (and, where a file has it, resistance R) against a noisy thermocouple
temperature, from one to a thousand heating and cooling branches per file, one load per
file. The model of every sample i of a file at load f, on the branch of its direction d,
is :func:`sma_fmu.identification.isobaric.terms.branch_curve` (two logistic stages, thermal
expansion, the stress law of the transformation strain) plus a strain offset. Fitted
(:mod:`~.layout` lists the unknowns, :mod:`~.starts` their starts and bounds):
- the hysteresis centres of each stage (:mod:`~.centres`): with one load the two centres at
  that load (the load slopes are not in the cost), with several the cooling line and the
  heating centre's lead (>= 0) at the lowest and highest load;
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
  ``lag="none"`` holds it at zero; ``lag="auto"``: :func:`~.sensor.choose_lag`).

Two fits in a row. The first (:mod:`~.first_fit`) holds the wire temperature at the
thermocouple profile and weights the strain by its effective variance: cheap, so it chooses
the widths and stages, finds the outlier cycles (:mod:`~.outliers`, left out by default)
and the lag's valley. The joint fit then starts from it: the wire temperature T_i is
lagged(profile), the profile piecewise linear with few knots per branch chosen from the
measured temperature alone, plus a knot wherever the strain moves fast (:mod:`~.profile`);
its knots are fitted jointly with the parameters against the residuals (profile - measured
temperature)/sigma_T, (model strain - measured strain)/sigma_eps (and resistance), each
sigma the data's own scatter (median absolute second difference). So the profile can move
only as far as the thermocouple noise allows, and a temperature residual much larger than
the noise says the model does not explain the data (:func:`~.outcome.verdict`). The
covariance s^2 (J^T J)^-1 of all unknowns (:mod:`~.covariance`) accounts for the
temperature noise. Levenberg-Marquardt with sparse direct steps (:mod:`~.solver`) runs on
a sparse Jacobian (:mod:`~.jacobian`); whether it converged is part of the outcome.
"""
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import sparse
from threadpoolctl import threadpool_limits

from sma_fmu.identification.isobaric.files import noise_level
from sma_fmu.identification.isobaric.first_fit import first_fit
from sma_fmu.identification.isobaric.jacobian import file_jacobian, scalar_sensitivities
from sma_fmu.identification.isobaric.lag import uniform_step
from sma_fmu.identification.isobaric.layout import Layout
from sma_fmu.identification.isobaric.outcome import (EXPLAINED_RATIO, IsobaricFit, check_inside,
                                                     outcome, residual_blocks)
from sma_fmu.identification.isobaric.outliers import OUTLIER_OPTIONS, bound_names, mark_outliers
from sma_fmu.identification.isobaric.profile import pointwise_error, temperature_profile
from sma_fmu.identification.isobaric.sensor import choose_lag, lag_sensitivity
from sma_fmu.identification.isobaric.solver import levenberg_marquardt
from sma_fmu.identification.isobaric.starts import PROFILE_BOUND, PROFILE_TOLERANCE_K, starts

__all__ = ["RESIDUAL_OPTIONS", "LAG_OPTIONS", "OUTLIER_OPTIONS", "IsobaricFit", "fit_isobaric",
           "prepare", "residual_blocks", "EXPLAINED_RATIO"]

RESIDUAL_OPTIONS = ("per-cycle", "none")
LAG_OPTIONS = ("fit", "none", "auto")
WIDTH_OPTIONS = ("auto", "separate", "shared")
STAGE_SHARE_MIN = 1e-3  # a second stage holding less than this share of M is not kept
STAGE_GAIN_MIN = 0.01   # nor one that lowers the cost by less than this fraction
JOINT_FTOL = 1e-7       # the joint fit has converged when 3 steps in a row gain less, relative
FIRST_FTOL = 1e-6       # the first fit only chooses and starts: a looser tolerance
_FLOOR = 1e-9           # relative floor of the noise estimates (noise-free data)
SCAN_EVALUATIONS = 6    # per starting lag before the full first fit
LAG_STARTS = (1 / 300, 1 / 100, 1 / 50, 1 / 25, 1 / 12, 1 / 6)   # of a cycle


@dataclass
class PreparedFile:
    """One file with its temperature profiles, sample step and noise estimates."""

    index: int
    data: object
    profile: object         # the joint fit's profile (knots also where the strain is steep)
    thermocouple: object    # the profile of the temperature alone (the first fit's wire)
    tc_error: np.ndarray    # its standard error at each sample [K] (floored, see prepare)
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


def prepare(data, index, residual="per-cycle"):
    """:class:`PreparedFile` of one IsobaricData: profiles, step, noise estimates."""
    def floor(values, estimate, least=1.0):
        return max(estimate, _FLOOR * max(float(np.ptp(values)), least))
    window = data.splitting.window_samples if data.splitting is not None else 5
    sigma = {"temperature": floor(data.temperature, noise_level(data.temperature)),
             "strain": floor(data.strain, noise_level(data.strain), 1e-3)}
    if data.resistance is not None:
        sigma["resistance"] = floor(data.resistance, noise_level(data.resistance))
    step, spread = uniform_step(data.time)
    thermocouple = temperature_profile(data.temperature, data.branches, data.time, window)
    profile = temperature_profile(data.temperature, data.branches, data.time, window,
                                  strain=data.strain)
    # the first fit's temperature uncertainty: the profile's own, or the share of the
    # thermocouple tolerance the joint fit's knot bound stands for, where that is larger
    error = np.maximum(pointwise_error(thermocouple), PROFILE_TOLERANCE_K / PROFILE_BOUND)
    return PreparedFile(index, data, profile, thermocouple, error, step, spread, sigma,
                        residual == "per-cycle")


class _Clock:
    """Counts model evaluations and moves a progress bar (``meter(total)``: tqdm-like or None)."""

    def __init__(self, meter):
        self.began = time.perf_counter()
        self.evaluations = 0
        self.bar = meter() if meter is not None else None

    def stage(self, text):
        if self.bar is not None:
            self.bar.set_description_str(text)

    def tick(self, cost=None):
        self.evaluations += 1
        if self.bar is not None:
            self.bar.update(1)
            if cost is not None:
                self.bar.set_postfix_str(f"cost {cost:.6g}", refresh=False)

    def close(self):
        if self.bar is not None:
            self.bar.close()


def _joint(prepared, layout, lower, upper, clock):
    """(residuals, jacobian, solve, order) of the joint fit of one layout."""
    order = layout.time_order(prepared)
    loads = [f.data.load for f in prepared]

    def residuals(x):
        out = np.concatenate(residual_blocks(x, layout, prepared))
        clock.tick(0.5 * float(out @ out))
        return out

    def jacobian(x):
        sensitivities = scalar_sensitivities(x, layout, loads)
        return sparse.vstack([b for f in prepared
                              for b in file_jacobian(x, layout, f, sensitivities)]).tocsr()

    def solve(x0, evaluations):
        return levenberg_marquardt(residuals, jacobian, x0, lower, upper, evaluations,
                                   ftol=JOINT_FTOL, order=order)
    return residuals, jacobian, solve, order


def _carry(old_layout, old_x, layout, vector):
    """``vector`` with every unknown the two layouts share taken from ``old_x`` (one width
    nu gives both nu_h and nu_c)."""
    out = vector.copy()
    old = {name: i for i, name in enumerate(old_layout.phys)}
    if "nu" in old:
        old["nu_h"] = old["nu_c"] = old["nu"]
    for i, name in enumerate(layout.phys):
        if name in old:
            out[i] = old_x[old[name]]
    k_old, k = len(old_layout.phys), len(layout.phys)
    out[k:len(layout.reported)] = old_x[k_old:len(old_layout.reported)]
    if len(old_x) == old_layout.size:     # a joint solution: its profile's knots too
        out[len(layout.reported):] = old_x[len(old_layout.reported):]
    return out


@dataclass
class _Trial:
    """A layout and its first fit: start vector and bounds (all unknowns), solution, weights."""

    layout: object
    vector: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    solution: object = None
    weights: list = None


def _first(prepared, trial, clock, evaluations=100, rounds=None):
    trial.solution, trial.weights = first_fit(prepared, trial.layout, trial.vector, trial.lower,
                                              trial.upper, evaluations, FIRST_FTOL,
                                              tick=clock.tick,
                                              **({"rounds": rounds} if rounds else {}))
    return trial


def _choose(prepared, base, layout_of, kind, widths, stages, lagged, outliers, clock):
    """The first fit: lag valley, outlier cycles, widths and stages. Returns (trial, stages,
    width kind, outlier cycles, the richer structures it did not keep: "widths", "stages")."""
    def trial_of(count, width_kind, fraction=0.01):
        layout = layout_of(count, width_kind)
        return _Trial(layout, *starts(prepared, layout, base, fraction))

    clock.stage("first fit")
    # on the data's own starting model first: a poor first fit can hide an odd cycle
    left_out = mark_outliers(prepared, layout_of(1, kind), trial_of(1, kind).vector,
                             outliers == "leave-out")
    if lagged:    # short fits from lags of 1/300 to 1/6 of a cycle; the best two go on
        scans = [_first(prepared, trial_of(1, kind, fraction), clock, SCAN_EVALUATIONS, 1)
                 for fraction in LAG_STARTS]
        scans.sort(key=lambda t: t.solution.cost)
        best = [_first(prepared, _Trial(t.layout, _with(t.vector, t.solution.x), t.lower,
                                        t.upper), clock) for t in scans[:2]]
    else:
        best = [_first(prepared, trial_of(1, kind), clock)]
    trial = min(best, key=lambda t: t.solution.cost)

    def outlying(trial):
        """``trial`` fitted again when its solution shows outlier cycles not yet left out (a
        poor fit hides them: a wider model can show more)."""
        found = mark_outliers(prepared, trial.layout, trial.solution.x, outliers == "leave-out")
        known = {(c["file"], c["cycle"]) for c in left_out}
        fresh = [c for c in found if (c["file"], c["cycle"]) not in known]
        left_out.extend(fresh)
        if fresh and outliers == "leave-out":
            trial = _first(prepared, _Trial(trial.layout, _with(trial.vector, trial.solution.x),
                                            trial.lower, trial.upper), clock)
        return trial

    trial = outlying(trial)

    def richer(count, width_kind):
        """The richer layout from the kept one's solution, and from the data's own starts."""
        fresh = trial_of(count, width_kind)
        carried = _Trial(fresh.layout, _carry(trial.layout, _with(trial.vector, trial.solution.x),
                                               fresh.layout, fresh.vector), fresh.lower, fresh.upper)
        tries = [_first(prepared, carried, clock)]
        if count == 2:
            tries.append(_first(prepared, fresh, clock))
        return min(tries, key=lambda t: t.solution.cost)

    rejected = []
    if widths == "auto":
        clock.stage("first fit: widths")
        wider = richer(1, "separate")
        if wider.solution.cost <= (1.0 - STAGE_GAIN_MIN) * trial.solution.cost:
            trial, kind = outlying(wider), "separate"
        else:
            rejected.append("widths")
    if stages == 2:
        clock.stage("first fit: stages")
        wider = richer(2, kind)
        w2 = wider.solution.x[wider.layout.phys.index("w2")]
        if w2 > STAGE_SHARE_MIN and \
                wider.solution.cost <= (1.0 - STAGE_GAIN_MIN) * trial.solution.cost:
            trial = outlying(wider)
        else:
            rejected.append("stages")
            stages = 1
    return trial, stages, kind, left_out, rejected


def _lag_starts(prepared, trial, start, solve, lagged):
    """The joint fit's starts: the first fit's solution, and with a lag the two best of short
    joint fits from it with the lag at the first fit's value and at 1/300 to 1/6 of a cycle
    (the first fit holds a smoothed temperature, and can put the lag in another valley)."""
    start = np.clip(start, trial.lower, trial.upper)
    if not lagged:
        return [start]
    candidates = [start]
    for fraction in LAG_STARTS:
        x = start.copy()
        for f in prepared:
            column = trial.layout.lags[f.index]
            period = f.data.splitting.period_samples * f.step if f.data.splitting else 100 * f.step
            x[column] = min(fraction * period, trial.upper[column])
        candidates.append(x)
    scans = sorted((solve(x, SCAN_EVALUATIONS) for x in candidates), key=lambda s: s.cost)
    return [s.x for s in scans[:2]]


def _second_look(prepared, base, layout_of, state, kind, rejected, clock, max_evaluations):
    """The joint fit's word on each richer structure the first fit did not keep (the first
    fit holds the temperature, and on filtered files, whose noise estimates are tiny, that
    can hide what the joint fit sees): tried from the joint solution, kept when it lowers
    the joint cost by STAGE_GAIN_MIN. Returns (state, width kind, stages, notes)."""
    notes, stages = [], state.layout.stages
    for what in rejected:
        count, width_kind = (stages, "separate") if what == "widths" else (2, kind)
        layout = layout_of(count, width_kind)
        vector, lower, upper = starts(prepared, layout, base)
        start = _carry(state.layout, state.solution.x, layout, vector)
        residuals, jacobian, solve, order = _joint(prepared, layout, lower, upper, clock)
        solution = solve(np.clip(start, lower, upper), max_evaluations)
        if what == "stages":
            w2 = solution.x[layout.phys.index("w2")]
            if w2 > STAGE_SHARE_MIN and \
                    solution.cost <= (1.0 - STAGE_GAIN_MIN) * state.solution.cost:
                state, stages = _Joint(layout, solution, jacobian, order, lower, upper, vector), 2
            else:
                notes.append(f"a second stage does not fit these data better (w2 = {w2:.3g}, "
                             f"cost {solution.cost:.6g} against {state.solution.cost:.6g} with "
                             f"one stage): one stage kept")
        elif solution.cost <= (1.0 - STAGE_GAIN_MIN) * state.solution.cost:
            state, kind = _Joint(layout, solution, jacobian, order, lower, upper, vector), \
                width_kind
        else:
            notes.append(f"separate heating and cooling widths do not fit these data better "
                         f"(cost {solution.cost:.6g} against {state.solution.cost:.6g} with "
                         f"one): one width kept")
    return state, kind, stages, notes


@dataclass
class _Joint:
    """A joint fit: its layout, solution, Jacobian function, order, bounds and start."""

    layout: object
    solution: object
    jacobian: object
    order: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    vector: np.ndarray


def _with(vector, head):
    """``vector`` with its first entries replaced by ``head``."""
    out = np.array(vector, dtype=float)
    out[:len(head)] = head
    return out


def _check_options(residual, lag, widths, stages, outliers):
    for name, value, options in (("residual", residual, RESIDUAL_OPTIONS),
                                 ("lag", lag, LAG_OPTIONS), ("widths", widths, WIDTH_OPTIONS),
                                 ("outliers", outliers, OUTLIER_OPTIONS)):
        if value not in options:
            raise ValueError(f"{name} must be one of {', '.join(options)}, got {value!r}")
    if stages not in (1, 2):
        raise ValueError(f"stages must be 1 or 2, got {stages!r}")


def fit_isobaric(files, base, residual="per-cycle", lag="fit", max_evaluations=300,
                 progress=None, stages=1, outliers="leave-out", widths="auto", meter=None):
    """Fit the isobaric files (list of IsobaricData) jointly; returns :class:`IsobaricFit`.

    ``lag``: "fit", "none" or "auto" (:func:`~.sensor.choose_lag`); ``stages``: 1, or 2 (a
    second stage, tried from the one-stage fit); ``widths``: "separate" (nu_h, nu_c),
    "shared" (one nu) or "auto" (shared, then separate kept only when it lowers the cost
    by STAGE_GAIN_MIN); ``outliers``: "leave-out" (cycles whose strain residual RMS exceeds
    OUTLIER_RATIO times the median cycle's are named and fitted again without their strain)
    or "keep". ``max_evaluations`` bounds the joint fit. ``progress`` (callable taking a
    line of text, or None) hears the notes; ``meter`` (a callable returning a tqdm-like
    bar, or None) shows the evaluations as they run. Raises MeasurementError when the
    fitted transformation leaves a file's temperature range.
    """
    _check_options(residual, lag, widths, stages, outliers)
    prepared = [prepare(data, index, residual) for index, data in enumerate(files)]
    loads = sorted({data.load for data in files})
    lag, lag_note = choose_lag(prepared, lag)
    if lag == "fit":   # the wire's temperature through the lag: knots at strain steps near
        for f in prepared:     # the turns would let the profile mimic the lag there
            f.profile = f.thermocouple

    def layout_of(count, kind):
        return Layout(prepared, base, len(loads) >= 2, any(d.absolute for d in files),
                      any(d.resistance is not None for d in files), lag == "fit", count, loads,
                      kind)
    clock = _Clock(meter)
    try:
        # the sparse solves gain nothing from BLAS threads, which only contend for the cores
        with threadpool_limits(limits=1, user_api="blas"):
            trial, stages, kind, left_out, rejected = _choose(
                prepared, base, layout_of, "separate" if widths == "separate" else "shared",
                widths, stages, lag == "fit", outliers, clock)
            first_evaluations = clock.evaluations
            clock.stage("joint fit")
            _, jacobian, solve, order = _joint(prepared, trial.layout, trial.lower, trial.upper,
                                               clock)
            start = _with(trial.vector, trial.solution.x)   # knots: the thermocouple's profile
            solution = min((solve(x, max_evaluations) for x in
                            _lag_starts(prepared, trial, start, solve, lag == "fit")),
                           key=lambda s: s.cost)
            state = _Joint(trial.layout, solution, jacobian, order, trial.lower, trial.upper,
                           trial.vector)
            state, kind, stages, notes = _second_look(prepared, base, layout_of, state, kind,
                                                      rejected, clock, max_evaluations)
    finally:
        clock.close()
    layout, solution = state.layout, state.solution
    seconds = time.perf_counter() - clock.began
    name = Path(str(getattr(base, "source", "the base file"))).name
    slope_notes = layout.settle(solution.x, name)
    if progress is not None:
        for note in ([lag_note] if lag_note else []) + notes + slope_notes:
            progress(note)
        if left_out:
            progress(f"outlier cycles {'left out' if outliers == 'leave-out' else 'kept'}: "
                     + "; ".join(c["name"] for c in left_out))
    on_bound = bound_names(layout, solution.x, state.lower, state.upper)
    fit = outcome(prepared, layout, solution, state.jacobian, state.order, state.vector, on_bound,
                  evaluations=clock.evaluations, seconds=seconds, outlier_cycles=left_out,
                  stages=stages, stage_note="; ".join(notes), slope_notes=slope_notes,
                  lag_note=lag_note, lag_option=lag,
                  sensor=[{"narrowing": lag_sensitivity(f), "unit": f.lag_unit} for f in prepared],
                  first_fit={"cost": float(trial.solution.cost),
                             "evaluations": first_evaluations,
                             "message": trial.solution.message})
    check_inside(fit.params, prepared)
    return fit
