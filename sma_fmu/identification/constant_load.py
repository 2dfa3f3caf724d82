"""Identify the constant-load model (spec section 4) from resistance-temperature sweeps.

Fitted: R_P, R_M, R_F [ohm], a_h, a_c [degC], b_h, b_c [degC/kg], xi_F_inf [1], f_F [kg]
and the domain size nu [1]. eps_T stays at the base file's value: only nu*eps_T sets the
transition width, and the remaining load term of dH(f) is too weak to separate the two.
Starting values come from the data: the saturated ends of each sweep, the temperature
half way through each transformation, and its width.

A base file with a second stage or separate widths nu_h/nu_c (what ``sma-fmu fit isobaric``
writes) already holds the transformation's temperatures and widths, fitted with every term
this one-stage fit lacks: they are kept (:func:`kept_from_base`), and the resistance data
complete the file with R_P, R_M, R_F, xi_F_inf and f_F.
"""
import math

import numpy as np

from sma_fmu.identification.least_squares import FitParameter, fit_parameters, percentage_errors
from sma_fmu.identification.measurements import MeasurementError
from sma_fmu.runtime.checks import direction_name
from sma_fmu.runtime.constant_load import branch_constants, branch_fractions
from sma_fmu.runtime.constants import BOLTZMANN, HEATING, KELVIN_OFFSET
from sma_fmu.runtime.sensing import mixed_fractions_of_resistance, sense_temperature

__all__ = ["FITTED", "MIN_LOADS", "model_resistance", "starting_parameters", "fit_constant_load",
           "sensing_comparison", "kept_from_base", "TRANSFORMATION"]

FITTED = ("R_P", "R_M", "R_F", "a_h", "b_h", "a_c", "b_c", "xi_F_inf", "f_F", "nu")
TRANSFORMATION = ("a_h", "b_h", "a_c", "b_c", "nu")   # kept from an isobaric fit's file


def kept_from_base(base):
    """The names of :data:`TRANSFORMATION` a fit keeps from ``base`` (a WireParameters):
    all of them when it has a second stage or its own widths nu_h/nu_c, else none."""
    if base.terms.two_stage or base.nu_h is not None or base.nu_c is not None:
        return TRANSFORMATION
    return ()
MIN_LOADS = 3               # distinct loads needed to identify the load dependence
MIN_RELATIVE_SPAN = 0.05    # a sweep must change R by 5 % of its mean to show a transformation


def _groups(data):
    """{(load, direction): indices} of the data rows."""
    groups = {}
    for index, key in enumerate(zip(data.load.tolist(), data.direction.tolist())):
        groups.setdefault(key, []).append(index)
    return {key: np.array(rows) for key, rows in groups.items()}


def model_resistance(params, data, groups=None):
    """Model resistance [ohm] at every data row (major branch of the row's direction)."""
    out = np.empty(data.temperature.size)
    resistance = params.R_P, params.R_M, params.R_F
    for (load, direction), rows in (groups or _groups(data)).items():
        constants = branch_constants(load, direction, params)
        half_mf = 0.5 * (resistance[1] + resistance[2]) - resistance[0]
        base = resistance[0] + constants.xi_F_min * (resistance[2] - resistance[0])
        for i in rows:
            out[i] = base + branch_fractions(data.temperature[i], constants)[0] * half_mf
    return out


def _crossing(temperature, resistance, level):
    """Temperature [degC] where a sweep (sorted by temperature) first falls below ``level``."""
    below = np.nonzero(resistance < level)[0]
    i = int(below[0]) if below.size else len(resistance) - 1
    if i == 0:
        return float(temperature[0])
    t0, t1, r0, r1 = temperature[i - 1], temperature[i], resistance[i - 1], resistance[i]
    return float(t0 + (level - r0) * (t1 - t0) / (r1 - r0)) if r1 != r0 else float(t1)


def _sweep_features(data, groups):
    """Per group: hot and cold resistance, centre, and 25-75 % width [K]; checks the data."""
    features = {}
    for (load, direction), rows in groups.items():
        order = rows[np.argsort(data.temperature[rows])]
        t, r = data.temperature[order], data.resistance[order]
        ends = max(2, len(order) // 10)
        cold, hot = float(np.median(r[:ends])), float(np.median(r[-ends:]))
        span = cold - hot
        name = data.files[int(data.source[rows[0]])]
        if len(order) < 8 or span < MIN_RELATIVE_SPAN * float(np.mean(r)):
            raise MeasurementError(
                f"{name}: no transformation in range at load {load:g} kg ({direction_name(direction)}): "
                f"resistance spans only {span:.3g} ohm between {t[0]:.4g} and {t[-1]:.4g} degC "
                f"({len(order)} rows); the sweep must cross the transformation")
        quarter = [_crossing(t, r, hot + share * span) for share in (0.75, 0.5, 0.25)]
        features[load, direction] = {"hot": hot, "cold": cold, "centre": quarter[1],
                                     "width": max(quarter[2] - quarter[0], 1e-3)}
    return features


def starting_parameters(data, base):
    """FitParameter unknowns with starting values estimated from the data, and bounds."""
    groups = _groups(data)
    loads = sorted({load for load, _ in groups})
    directions = {direction for _, direction in groups}
    name = ", ".join(str(f) for f in data.files)
    if len(loads) < MIN_LOADS:
        raise MeasurementError(f"{name}: {len(loads)} load(s) ({', '.join(f'{f:g}' for f in loads)} kg); "
                               f"identifying the load dependence needs at least {MIN_LOADS}")
    if directions != {1, -1}:
        raise MeasurementError(f"{name}: only {direction_name(directions.pop())} sweeps; "
                               f"heating and cooling sweeps are both needed")
    features = _sweep_features(data, groups)
    light, heavy = loads[0], loads[-1]
    r_p = min(features[light, d]["hot"] for d in (1, -1))
    r_mf = max(features[light, d]["cold"] for d in (1, -1))
    residual = np.mean([features[heavy, d]["hot"] for d in (1, -1)]) - r_p
    xi_heavy = min(max(residual / (r_mf - r_p), 1e-3), 0.9)
    centres = {}
    for direction in (1, -1):
        f = np.array(loads)
        tau = np.array([features[load, direction]["centre"] for load in loads])
        centres[direction] = np.polyfit(f, tau, 1)  # slope [degC/kg], intercept [degC]
    widths = [(features[k]["centre"] + KELVIN_OFFSET, features[k]["width"]) for k in features]
    # 25-75 % width of the logistic: 2 ln 3 k_B T^2 / dH
    energy = np.mean([2.0 * math.log(3.0) * BOLTZMANN * t * t / w for t, w in widths])
    midpoint = 0.5 * (r_p + r_mf)
    top = 3.0 * float(data.resistance.max())
    return [
        FitParameter("R_P", r_p, 1e-3, midpoint),
        FitParameter("R_M", r_mf, midpoint, top),
        FitParameter("R_F", r_mf, midpoint, top),
        FitParameter("a_h", float(centres[HEATING][1]), -100.0, 300.0),
        FitParameter("b_h", float(centres[HEATING][0]), -2000.0, 2000.0),
        FitParameter("a_c", float(centres[-1][1]), -100.0, 300.0),
        FitParameter("b_c", float(centres[-1][0]), -2000.0, 2000.0),
        FitParameter("xi_F_inf", min(xi_heavy / (1.0 - math.exp(-1.0)), 0.9), 0.0, 0.99),
        FitParameter("f_F", heavy, 1e-3 * heavy, 100.0 * heavy),
        FitParameter("nu", energy / base.eps_T, 1e-2, 1e6),
    ]


def _group_stats(data, model, groups):
    out = []
    for (load, direction), rows in sorted(groups.items()):
        errors = percentage_errors(model[rows], data.resistance[rows])
        out.append({"load_kg": load, "direction": direction_name(direction), "points": int(rows.size),
                    "mape_percent": float(errors.mean()),
                    "max_abs_error_ohm": float(np.max(np.abs(model[rows] - data.resistance[rows])))})
    return out


def sensing_comparison(params, data):
    """Temperature-sensing model vs data (paper Fig. 5): T errors where R is not saturated.

    Returns (sensed temperatures [degC], saturated flags, report dict). ``core`` restricts
    to 5 % <= xi_MF/M <= 95 %, where a resistance reading carries most temperature information.
    """
    sensed = np.empty(data.temperature.size)
    saturated = np.zeros(data.temperature.size, dtype=bool)
    core = np.zeros(data.temperature.size, dtype=bool)
    for i, (r, f, d) in enumerate(zip(data.resistance, data.load, data.direction)):
        result = sense_temperature(float(r), float(f), int(d), params)
        sensed[i], saturated[i] = result.temperature, result.saturated
        constants = branch_constants(float(f), int(d), params)
        share = mixed_fractions_of_resistance(float(r), constants, params)[0] / constants.M
        core[i] = 0.05 <= share <= 0.95
    error = sensed - data.temperature

    def summary(mask):
        if not mask.any():
            return {"points": 0, "rmse_K": None, "max_abs_K": None}
        return {"points": int(mask.sum()), "rmse_K": float(np.sqrt(np.mean(error[mask] ** 2))),
                "max_abs_K": float(np.max(np.abs(error[mask])))}

    report = {"unsaturated": summary(~saturated), "core_5_95_percent": summary(core & ~saturated),
              "saturated_points": int(saturated.sum())}
    return sensed, saturated, report


def fit_constant_load(data, base):
    """Fit :data:`FITTED` to constant-load data; returns (FitResult, report dict)."""
    groups = _groups(data)
    kept = kept_from_base(base)
    unknowns = [p for p in starting_parameters(data, base) if p.name not in kept]

    def residuals(params):
        return model_resistance(params, data, groups) - data.resistance

    result = fit_parameters(residuals, base, unknowns)
    model = result.residuals + data.resistance
    errors = percentage_errors(model, data.resistance)
    _, _, sensing = sensing_comparison(result.params, data)
    report = {
        "experiment": "constant-load",
        "files": [str(f) for f in data.files],
        "points": int(data.resistance.size),
        "parameters": result.table(),
        "covariance": result.covariance_table(),
        "fixed_from_base": {"eps_T": base.eps_T, **{name: getattr(base, name) for name in kept}},
        "kept_from_base": {
            "parameters": list(kept),
            "note": f"kept from the base file: {', '.join(kept)} (its transformation, fitted "
                    f"with a second stage or separate widths nu_h/nu_c, terms this fit lacks)"}
        if kept else None,
        "mape_percent": float(errors.mean()),
        "max_abs_error_ohm": float(np.max(np.abs(result.residuals))),
        "rmse_ohm": float(np.sqrt(np.mean(result.residuals ** 2))),
        "per_load_and_direction": _group_stats(data, model, groups),
        "transformation_temperatures_degC": {
            f"{load:g} kg": {"heating": result.params.a_h + result.params.b_h * load,
                             "cooling": result.params.a_c + result.params.b_c * load}
            for load in sorted({k[0] for k in groups})},
        "temperature_sensing": sensing,
        "solver": {"converged": result.converged, "message": result.message,
                   "evaluations": result.evaluations, "seconds": result.seconds},
    }
    return result, report
