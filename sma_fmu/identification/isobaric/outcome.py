"""What an isobaric fit found, assembled from the joint fit's solution: the covariance, the
parameter-file names and values, the residuals beside their noise, the verdict, and the
refusal of a model whose transformation leaves the data's temperature range."""
from dataclasses import dataclass, field

import numpy as np

from sma_fmu.identification.isobaric.covariance import (named, named_values,
                                                        reported_covariance, wire_covariance)
from sma_fmu.identification.isobaric.jacobian import file_model, file_state
from sma_fmu.identification.isobaric.residual_parts import strain_parts
from sma_fmu.identification.isobaric.resolution import floor_notes
from sma_fmu.identification.isobaric.terms import branch_curve
from sma_fmu.identification.measurements import MeasurementError
from sma_fmu.runtime.constant_load import hysteresis_centre
from sma_fmu.runtime.constants import COOLING, HEATING

__all__ = ["IsobaricFit", "EXPLAINED_RATIO", "verdict", "residual_blocks", "check_inside",
           "outcome"]

EXPLAINED_RATIO = 1.5   # residual RMS above this many noise estimates: not explained


@dataclass
class IsobaricFit:
    """Outcome of :func:`~.fit.fit_isobaric`."""

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
    noise: dict               # the same keys: the noise the verdict judged against, per file
    #                           the larger of estimate and quantisation floor (RMS over the files)
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
    stage_note: str = ""      # why a wider model asked for was not kept
    undetermined: list = None  # unknowns no residual touches (levels of left-out cycles)
    file_rms: list = None     # per file: {"temperature_K", "strain"(, "resistance_ohm")} RMS
    slope_notes: list = field(default_factory=list)   # which load slopes were fixed, from where
    lag_note: str = ""        # what --lag auto chose and why
    lag_option: str = "fit"   # "fit" or "none", as used
    first_fit: dict = None    # the first fit (profile held): cost, evaluations, message
    sensor: list = None       # per file: {"narrowing": K per unit of lag, "unit": s or samples}
    strain_parts: list = None  # per file: the strain residual by direction, phase and cycle
    noise_estimates: dict = None  # the keys of ``noise``: the estimates (the weights) alone
    noise_floors: dict = None     # the keys of ``noise``: the files' quantisation floors
    floor_notes: list = field(default_factory=list)   # which noise was floored, per file
    floors: list = None       # per file: the keys of ``sigma``: quantisation floors


def verdict(rms, noise, floored=()):
    """One line: whether the residuals are what the noise predicts (``noise``: the estimates,
    or for the keys in ``floored`` the file's quantisation where that is larger)."""
    ratios = {key: rms[key] / noise[key] for key in rms if rms[key] is not None and noise[key]}
    unit = {"temperature_K": " K", "strain": "", "resistance_ohm": " ohm"}

    def what(key):
        return "noise (floored at the file's resolution)" if key in floored else "noise estimate"
    worst = [f"{key.split('_')[0]} residual {rms[key]:.3g}{unit[key]} is {ratio:.1f}x its "
             f"{what(key)} {noise[key]:.3g}{unit[key]}" for key, ratio in ratios.items()
             if ratio > EXPLAINED_RATIO]
    if worst:
        return "the model does not explain the data: " + "; ".join(worst) + \
            (" (the wire temperature had to move beyond the thermocouple noise)"
             if ratios.get("temperature_K", 0) > EXPLAINED_RATIO else "")
    return ("the model explains the data within the noise: residuals "
            + ", ".join(f"{key.split('_')[0]} {ratio:.2f}x" for key, ratio in ratios.items())
            + " their noise estimates"
            + (f" ({', '.join(k.split('_')[0] for k in ratios if k in floored)} floored at the "
               f"file's resolution)" if any(k in floored for k in ratios) else ""))


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


def _half_way(params, load, direction, low, high):
    """Temperature [degC] in [low, high] where the model's q crosses 1/2, or None."""
    grid = np.linspace(low, high, 4001)
    _, _, q = branch_curve(grid, load, direction, params, 1.0)
    above = q >= 0.5
    if above.all() or not above.any():
        return None
    i = int(np.argmax(above != above[0]))
    return float(grid[i])


def check_inside(params, prepared):
    """Refuse (MeasurementError naming the file) a model whose transformation, heating or
    cooling, is not half done somewhere inside the file's measured temperature range."""
    for f in prepared:
        low, high = float(np.min(f.data.temperature)), float(np.max(f.data.temperature))
        for direction, word in ((HEATING, "heating"), (COOLING, "cooling")):
            if _half_way(params, f.data.load, direction, low, high) is None:
                centre = hysteresis_centre(f.data.load, direction, params)
                raise MeasurementError(
                    f"{f.data.path}: the fitted model's {word} transformation lies outside the "
                    f"data's temperature range {low:.4g} to {high:.4g} degC (its centre at "
                    f"{f.data.load:g} kg: {centre:.4g} degC); the fit is refused, nothing written")


def _rms(parts, prepared):
    """(overall RMS, noise RMS, per-file RMS) of the residual blocks, in their units; the noise
    RMS for each of the files' ``judged``, ``sigma`` (estimates) and ``floor`` (quantisation),
    so ``noise`` is {"judged", "sigma", "floor"} of {key: RMS}."""
    rms = {"temperature_K": [], "strain": [], "resistance_ohm": []}
    noise = {kind: {"temperature_K": [], "strain": [], "resistance_ohm": []}
             for kind in ("judged", "sigma", "floor")}
    i, file_rms = 0, []
    for f in prepared:
        file_rms.append({})
        for key, sigma_key in (("temperature_K", "temperature"), ("strain", "strain"),
                               ("resistance_ohm", "resistance")):
            if sigma_key in f.sigma:
                kept = f.weight > 0 if sigma_key != "temperature" else slice(None)
                rms[key].append(parts[i][kept] * f.sigma[sigma_key])
                for kind in noise:
                    noise[kind][key].append(np.full(parts[i][kept].size,
                                                    getattr(f, kind)[sigma_key]))
                kept_rows = rms[key][-1]    # none when every cycle of the file was left out
                file_rms[-1][key] = float(np.sqrt(np.mean(kept_rows ** 2))) if kept_rows.size \
                    else float("nan")
                i += 1
    rms = {key: float(np.sqrt(np.mean(np.concatenate(v) ** 2))) if v else None
           for key, v in rms.items()}
    noise = {kind: {key: float(np.sqrt(np.mean(np.concatenate(v) ** 2))) if v else None
                    for key, v in values.items()} for kind, values in noise.items()}
    return rms, noise, file_rms


def outcome(prepared, layout, solution, jacobian, order, first, on_bound, **extra):
    """:class:`IsobaricFit` of the joint ``solution`` (``first``: the starting vector;
    ``extra``: the remaining fields)."""
    first = first[:len(layout.reported)]
    jac = jacobian(solution.x)
    m, n = solution.fun.size, layout.size
    dof = max(m - n - sum(int(np.sum(f.weight == 0)) for f in prepared), 1)
    factor = float(np.sum(solution.fun ** 2)) / dof
    k = len(layout.reported)
    cov, dead = reported_covariance(jac, factor, k, order)
    names, to_names = named(layout, solution.x)
    if not np.all(np.isfinite(cov)):
        raise MeasurementError(f"{layout.paths}: the fit's covariance is not finite; the data do "
                               f"not determine the unknowns")
    params = layout.params(solution.x)
    cov[dead, :], cov[:, dead] = 0.0, 0.0    # undetermined: reported as a zero error, named
    undetermined = [layout.reported[i] for i in np.nonzero(dead)[0]]
    errors = np.sqrt(np.clip(np.diag(cov), 0, None))
    cov_named = to_names @ cov @ to_names.T
    values = named_values(layout, solution.x, names)
    parts = residual_blocks(solution.x, layout, prepared)
    states = [file_state(solution.x, layout, f) for f in prepared]
    rms, noise, file_rms = _rms(parts, prepared)
    keys = {"temperature": "temperature_K", "strain": "strain", "resistance": "resistance_ohm"}
    floored = {keys[key] for f in prepared for key in f.sigma if f.floor[key] > f.sigma[key]}
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
        directions=[s[3] for s in states], row_levels=[s[4] for s in states],
        wire_bounds=[s[5] for s in states], sigma=[f.sigma for f in prepared], residual_rms=rms,
        noise=noise["judged"], verdict=verdict(rms, noise["judged"], floored),
        noise_estimates=noise["sigma"], noise_floors=noise["floor"],
        floor_notes=floor_notes(prepared), floors=[f.floor for f in prepared], variance_factor=factor, dof=dof,
        profile_unknowns=n - k, knots_per_branch=[f.profile.knots_per_branch for f in prepared],
        converged=bool(solution.status > 0), message=str(solution.message), on_bound=on_bound,
        file_rms=file_rms, undetermined=undetermined,
        strain_parts=strain_parts(prepared, layout, solution.x, states), **extra)
