"""Identify the constant-load model (spec sections 2-4, with the optional model terms) from
isobaric thermal cycling.

The data: strain eps (and, where a file has it, resistance R) against a noisy thermocouple
temperature, from one to a thousand heating and cooling branches per file, one load per
file. The model of every sample i of a file at load f, on the branch of its direction d,
is :func:`sma_fmu.identification.isobaric.terms.branch_curve` (two logistic stages, thermal
expansion, the stress law of the transformation strain) plus a strain offset. Fitted
(:mod:`~.layout` lists the unknowns, :mod:`~.starts` their starts and bounds):
- the hysteresis centres of each stage (:mod:`~.centres`): with one load the two centres at
  that load (the load slopes are not in the cost), with several the cooling line and the
  heating centre's lead (>= 0) at the lowest and highest load; with
  ``centre_law="clausius-clapeyron"`` and three stresses or more, each direction's share of
  the slope that follows the transformation strain, fitted last (:mod:`~.centre_law`);
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
the noise says the model does not explain the data (:func:`~.outcome.verdict`; it judges
against the estimate or, where that is smaller, the file's quantisation,
:mod:`~.resolution`). The
covariance s^2 (J^T J)^-1 of all unknowns (:mod:`~.covariance`) accounts for the
temperature noise. Levenberg-Marquardt with sparse direct steps (:mod:`~.solver`) runs on
a sparse Jacobian (:mod:`~.jacobian`); whether it converged is part of the outcome.
"""
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

from sma_fmu.identification.isobaric.centres import CENTRE_LAWS, SHARE_STRESSES
from sma_fmu.identification.isobaric.files import noise_level
from sma_fmu.identification.isobaric.lag import uniform_step
from sma_fmu.identification.isobaric.layout import Layout
from sma_fmu.identification.isobaric.outcome import (EXPLAINED_RATIO, IsobaricFit, check_inside,
                                                     outcome, residual_blocks)
from sma_fmu.identification.isobaric.outliers import OUTLIER_OPTIONS, bound_names
from sma_fmu.identification.isobaric.profile import pointwise_error, temperature_profile
from sma_fmu.identification.isobaric.resolution import judged_noise
from sma_fmu.identification.isobaric.sensor import choose_lag, lag_sensitivity
from sma_fmu.identification.isobaric.starts import PROFILE_BOUND, PROFILE_TOLERANCE_K
from sma_fmu.identification.isobaric.structure import (Clock, Joint, choose, joint, joint_starts,
                                                       law_look, second_look, simpler_look,
                                                       with_head)

__all__ = ["RESIDUAL_OPTIONS", "LAG_OPTIONS", "OUTLIER_OPTIONS", "IsobaricFit", "fit_isobaric",
           "prepare", "residual_blocks", "EXPLAINED_RATIO"]

RESIDUAL_OPTIONS = ("per-cycle", "none")
LAG_OPTIONS = ("fit", "none", "auto")
WIDTH_OPTIONS = ("auto", "separate", "shared")
_FLOOR = 1e-9           # relative floor of the noise estimates (noise-free data)


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
    floor: dict = None      # the quantisation of each column's written step (same keys, units)
    judged: dict = None     # what the verdict judges against: the larger of sigma and floor
    held: bool = False      # a temperature without scatter: the knots held to its own fit

    def __post_init__(self):
        if self.weight is None:
            self.weight = np.ones(self.data.strain.size)
        if self.judged is None:
            self.floor, self.judged = judged_noise(self.sigma,
                                                   getattr(self.data, "resolution", {}))

    @property
    def lag_unit(self):
        return "s" if self.data.time is not None else "samples"


def prepare(data, index, residual="per-cycle"):
    """:class:`PreparedFile` of one IsobaricData: profiles, step, noise estimates (the
    weights) and the noise the verdict judges against (:mod:`~.resolution`)."""
    def floor(values, estimate, least=1.0):
        return max(estimate, relative_floor(values, least))
    window = data.splitting.window_samples if data.splitting is not None else 5
    scatter = noise_level(data.temperature)
    sigma = {"temperature": floor(data.temperature, scatter),
             "strain": floor(data.strain, noise_level(data.strain), 1e-3)}
    if data.resistance is not None:
        sigma["resistance"] = floor(data.resistance, noise_level(data.resistance))
    step, spread = uniform_step(data.time)
    thermocouple = temperature_profile(data.temperature, data.branches, data.time, window)
    profile = temperature_profile(data.temperature, data.branches, data.time, window,
                                  strain=data.strain)
    # the thermocouple profile's standard error, or the share of the thermocouple tolerance
    # the joint fit's knot bound stands for, where that is larger: the first fit's
    # temperature uncertainty, and PROFILE_BOUND of it the joint fit's knot bound. A
    # temperature without any scatter (computed, or resampled on a grid) is the wire's: no
    # noise prices the profile's moves, so within the tolerance they would absorb the
    # model's misfit and shift the centres (held_temperature)
    written = judged_noise(sigma, getattr(data, "resolution", {}))[0]["temperature"]
    held = held_temperature(scatter, max(relative_floor(data.temperature), written))
    error = np.maximum(pointwise_error(thermocouple),
                       sigma["temperature"] if held else PROFILE_TOLERANCE_K / PROFILE_BOUND)
    return PreparedFile(index, data, profile, thermocouple, error, step, spread, sigma,
                        residual == "per-cycle", held=held)


def relative_floor(values, least=1.0):
    """The least noise [the values' unit] a column is weighted with: _FLOOR of its range (of
    ``least`` where the range is smaller), so that a noise-free column keeps a finite weight."""
    return _FLOOR * max(float(np.ptp(values)), least)


def held_temperature(scatter, floor):
    """True when a file's temperature shows no scatter beyond its written digits: its noise
    estimate ``scatter`` [K] (:func:`~.files.noise_level`) is no larger than ``floor`` [K],
    the larger of its quantisation (:mod:`~.resolution`) and :func:`relative_floor`. Its
    wire temperature is then held at the temperature's own fit: the knots move only by their
    standard error, not by the thermocouple tolerance."""
    return bool(scatter <= floor)


def _check_options(residual, lag, widths, stages, outliers, centre_law):
    for name, value, options in (("residual", residual, RESIDUAL_OPTIONS),
                                 ("lag", lag, LAG_OPTIONS), ("widths", widths, WIDTH_OPTIONS),
                                 ("outliers", outliers, OUTLIER_OPTIONS),
                                 ("centre_law", centre_law, CENTRE_LAWS)):
        if value not in options:
            raise ValueError(f"{name} must be one of {', '.join(options)}, got {value!r}")
    if stages not in (1, 2):
        raise ValueError(f"stages must be 1 or 2, got {stages!r}")


def fit_isobaric(files, base, residual="per-cycle", lag="fit", max_evaluations=300,
                 progress=None, stages=1, outliers="leave-out", widths="auto", meter=None,
                 centre_law="linear"):
    """Fit the isobaric files (list of IsobaricData) jointly; returns :class:`IsobaricFit`.

    ``lag``: "fit", "none" or "auto" (:func:`~.sensor.choose_lag`); ``stages``: 1, or 2 (a
    second stage, tried from the one-stage fit); ``widths``: "separate" (nu_h, nu_c),
    "shared" (one nu) or "auto" (shared, then separate kept only when it lowers the cost
    by STAGE_GAIN_MIN); ``outliers``: "leave-out" (cycles whose strain residual RMS exceeds
    OUTLIER_RATIO times the median cycle's are named and fitted again without their strain)
    or "keep"; ``centre_law``: "linear" or "clausius-clapeyron" (the shares of
    :class:`~.centres.StrainFollowingCentres`, tried last from the joint fit with linear
    centres when the files hold three stresses or more, else kept from ``base``).
    ``max_evaluations`` bounds the joint fit. ``progress`` (callable taking a
    line of text, or None) hears the notes; ``meter`` (a callable returning a tqdm-like
    bar, or None) shows the evaluations as they run. Raises MeasurementError when the
    fitted transformation leaves a file's temperature range.
    """
    _check_options(residual, lag, widths, stages, outliers, centre_law)
    prepared = [prepare(data, index, residual) for index, data in enumerate(files)]
    loads = sorted({data.load for data in files})
    lag, lag_note = choose_lag(prepared, lag)
    if lag == "fit":   # the wire's temperature through the lag: knots at strain steps near
        for f in prepared:     # the turns would let the profile mimic the lag there
            f.profile = f.thermocouple

    # the shares are fitted last, from the fit with linear centres
    fit_law = centre_law == "clausius-clapeyron" and len(loads) >= SHARE_STRESSES

    def layout_of(count, kind, law="linear" if fit_law else centre_law):
        return Layout(prepared, base, len(loads) >= 2, any(d.absolute for d in files),
                      any(d.resistance is not None for d in files), lag == "fit", count, loads,
                      kind, law)
    clock = Clock(meter)
    try:
        # the sparse solves gain nothing from BLAS threads, which only contend for the cores
        with threadpool_limits(limits=1, user_api="blas"):
            trial, stages, kind, left_out, rejected = choose(
                prepared, base, layout_of, "separate" if widths == "separate" else "shared",
                widths, stages, lag == "fit", outliers, clock)
            first_evaluations = clock.evaluations
            clock.stage("joint fit")
            _, jacobian, solve, order = joint(prepared, trial.layout, trial.lower, trial.upper,
                                               clock)
            start = with_head(trial.vector, trial.solution.x)   # knots: the thermocouple's profile
            solution = min((solve(x, max_evaluations) for x in
                            joint_starts(prepared, trial, start, solve, lag == "fit")),
                           key=lambda s: s.cost)
            state = Joint(trial.layout, solution, jacobian, order, trial.lower, trial.upper,
                           trial.vector)
            state, kind, stages, notes = second_look(prepared, base, layout_of, state, kind,
                                                      rejected, clock, max_evaluations)
            state, stages, note = simpler_look(prepared, base, layout_of, state, kind, clock,
                                               max_evaluations)
            notes += [note] if note else []
            if fit_law:
                state, note = law_look(prepared, base,
                                       lambda count, kind: layout_of(count, kind, centre_law),
                                       state, kind, clock, max_evaluations)
                notes += [note] if note else []
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
