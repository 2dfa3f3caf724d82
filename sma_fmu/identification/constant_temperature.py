"""Identify the constant-temperature model (spec section 7) from load cycles at fixed temperature.

Fitted: eps_f [J] and nu_f [1], which set the critical load f_c = eps_f N/(g x_f) and the
width of the stress-induced transformation. Everything else (resistances, the start state
from the constant-load model) comes from the base parameter file, normally the result of a
constant-load fit. Starting values come from the data: R against the running maximum load
gives the critical load and the width.
"""
import math

import numpy as np

from sma_fmu.identification.least_squares import FitParameter, fit_parameters, percentage_errors
from sma_fmu.identification.measurements import MeasurementError
from sma_fmu.runtime.constant_temperature import ConstantTemperatureModel
from sma_fmu.runtime.constants import BOLTZMANN, KELVIN_OFFSET, STANDARD_GRAVITY

__all__ = ["FITTED", "model_resistance", "starting_parameters", "fit_constant_temperature"]

FITTED = ("eps_f", "nu_f")
MIN_CHANGE_SHARE = 0.1  # the data must show 10 % of the largest possible resistance change


def model_resistance(params, experiments):
    """Model resistance [ohm] of every row of every experiment, concatenated."""
    return np.concatenate([
        ConstantTemperatureModel(e.temperature, params).resistance_sequence(e.load.tolist())
        for e in experiments])


def _crossing(loads, progress, level):
    """Load [kg] where the (non-decreasing) ``progress`` first reaches ``level``."""
    above = np.nonzero(progress >= level)[0]
    i = int(above[0]) if above.size else len(loads) - 1
    if i == 0 or progress[i] == progress[i - 1]:
        return float(loads[i])
    return float(loads[i - 1] + (level - progress[i - 1]) * (loads[i] - loads[i - 1])
                 / (progress[i] - progress[i - 1]))


def starting_parameters(experiments, base):
    """FitParameter unknowns (eps_f, nu_f) estimated from the data, with bounds."""
    critical, slopes = [], []
    for e in experiments:
        start = ConstantTemperatureModel(e.temperature, base).start
        possible = abs(base.R_M - base.R_F) * start.xi_M
        # the ratchet makes R a function of the largest load so far, from R at the first row
        # to R at the largest load; progress runs from 0 to 1 whichever way R moves
        running = np.maximum.accumulate(e.load)
        change = float(e.resistance[int(np.argmax(running))] - e.resistance[0])
        if abs(change) < MIN_CHANGE_SHARE * possible:
            raise MeasurementError(
                f"{e.path}: no transformation in range: the resistance changes by only "
                f"{abs(change):.3g} ohm (up to {possible:.3g} ohm possible); the load must pass "
                f"the critical load")
        order = np.argsort(running, kind="stable")
        loads = running[order]
        progress = np.maximum.accumulate((e.resistance[order] - e.resistance[0]) / change)
        f25, f50, f75 = (_crossing(loads, progress, share) for share in (0.25, 0.5, 0.75))
        critical.append(f50)
        width = max(f75 - f25, 1e-4)
        # phi = 1/(1 + exp(k (f_c - f))): the 25-75 % width is 2 ln 3 / k
        slopes.append((2.0 * math.log(3.0) / width, e.temperature))
    f_c = float(np.mean(critical))
    k, temperature = np.mean([s for s, _ in slopes]), np.mean([t for _, t in slopes])
    nu_f = k * base.N * BOLTZMANN * (temperature + KELVIN_OFFSET) / (STANDARD_GRAVITY * base.x_f)
    eps_f = STANDARD_GRAVITY * f_c * base.x_f / base.N
    return [FitParameter("eps_f", eps_f, eps_f * 1e-3, eps_f * 1e3),
            FitParameter("nu_f", float(nu_f), float(nu_f) * 1e-3, float(nu_f) * 1e3)]


def fit_constant_temperature(experiments, base):
    """Fit :data:`FITTED` to constant-temperature experiments; returns (FitResult, report)."""
    measured = np.concatenate([e.resistance for e in experiments])

    def residuals(params):
        return model_resistance(params, experiments) - measured

    result = fit_parameters(residuals, base, starting_parameters(experiments, base))
    model = result.residuals + measured
    per_file, offset = [], 0
    for e in experiments:
        rows = slice(offset, offset + e.load.size)
        offset += e.load.size
        per_file.append({"file": str(e.path), "temperature_C": e.temperature, "points": int(e.load.size),
                         "mape_percent": float(percentage_errors(model[rows], measured[rows]).mean()),
                         "max_abs_error_ohm": float(np.max(np.abs(result.residuals[rows])))})
    params = result.params
    report = {
        "experiment": "constant-temperature",
        "files": [str(e.path) for e in experiments],
        "points": int(measured.size),
        "parameters": result.table(),
        "covariance": result.covariance_table(),
        "critical_load_kg": params.eps_f * params.N / (STANDARD_GRAVITY * params.x_f),
        "mape_percent": float(percentage_errors(model, measured).mean()),
        "max_abs_error_ohm": float(np.max(np.abs(result.residuals))),
        "rmse_ohm": float(np.sqrt(np.mean(result.residuals ** 2))),
        "per_file": per_file,
        "solver": {"converged": result.converged, "message": result.message,
                   "evaluations": result.evaluations, "seconds": result.seconds},
    }
    return result, report
