"""Gain and phase margins of a scenario's PI loop, linearised where the wire is steepest.

The loop of spec section 11, sampled at h: u_k = Kp e_k + Ki I_k with I_(k+1) = I_k + h e_k
(forward Euler), T_(k+1) = T_room + a (T_k - T_room) + K_th (1 - a) u_k with
a = exp(-h / tau_th) (the exact thermal step, :mod:`sma_fmu.runtime.thermal`), and, on a
branch, R_k - R_op = -g (T_k - T_op) with g = -dR/dT > 0 (R falls as the wire heats; the
error e = R - R_ref asks for heat). With e = R - R_ref the loop is negative feedback through

    L(z) = (Kp + Ki h / (z - 1)) * g K_th (1 - a) / (z - a)

The feedforward and the phase-lag filter are outside the loop and do not enter; the sensor
noise does not change L; the clamp at 0 W and a drive limit are the nonlinearities the
linearisation leaves out. **choice**: the operating point is where the loop gain is largest,
the steepest |dR/dT| of the major branches (both directions, every load of the scenario)
over the resistances the reference visits; the margins there are the smallest the loop
has. The frequency response is python-control's (:func:`control.frequency_response` of the
discrete transfer function) on a grid up to the Nyquist frequency pi / h, where a margin
often lies (L(-1) is real): the gain margin is 1/|L| where the phase crosses -180 degrees
(the Nyquist frequency included), the phase margin 180 degrees plus the phase where |L|
first falls through 1.
"""
import math

import control
import numpy as np

from sma_fmu.runtime.constant_load import constant_load_resistance
from sma_fmu.runtime.constants import COOLING, HEATING
from sma_fmu.runtime.thermal import step_decay

__all__ = ["steepest_slope", "loop_transfer", "stability_margins", "loop_margins"]

_GRID_K = 0.05          # [K] spacing of the temperature grid the slope is searched on
_SPAN_K = 160.0         # [K] above T_room the grid reaches (past every branch's end)
_POINTS = 4000          # frequencies per decade band of the response grid


def steepest_slope(scenario):
    """(g [ohm/K], T [degC], load [kg], direction): the largest |dR/dT| of the major branches
    at the scenario's loads where R lies within the reference's range."""
    params = scenario.params
    low, high = scenario.reference.bounds()
    temperatures = params.T_room + np.arange(0.0, _SPAN_K, _GRID_K)
    best = (0.0, math.nan, math.nan, HEATING)
    for load in sorted(set(scenario.load.values)):
        for direction in (HEATING, COOLING):
            values = np.array([constant_load_resistance(float(t), load, direction, params)
                               for t in temperatures])
            slopes = np.abs(np.gradient(values, temperatures))
            inside = (values >= low) & (values <= high)
            if inside.any():
                index = int(np.argmax(np.where(inside, slopes, -1.0)))
                if slopes[index] > best[0]:
                    best = (float(slopes[index]), float(temperatures[index]), load, direction)
    return best


def loop_transfer(Kp, Ki, slope, params, step_s):
    """L(z) (python-control, sampling time ``step_s`` [s]) of gains Kp [W/ohm], Ki
    [W/(ohm.s)] on a branch of slope ``slope`` g [ohm/K] (see the module docstring)."""
    a = step_decay(step_s, params.tau_th)
    controller = control.tf([Kp, Ki * step_s - Kp], [1.0, -1.0], dt=step_s)
    plant = control.tf([slope * params.K_th * (1.0 - a)], [1.0, -a], dt=step_s)
    return controller * plant


def stability_margins(loop, step_s):
    """{"gain_margin", "gain_margin_dB", "phase_margin_deg", "gain_crossover_Hz",
    "phase_crossover_Hz"} of the discrete loop ``loop`` (see the module docstring); inf
    and None where there is no crossing."""
    nyquist = math.pi / step_s
    omega = np.unique(np.concatenate((np.geomspace(1e-4, nyquist, 6 * _POINTS), [nyquist])))
    response = control.frequency_response(loop, omega)
    magnitude = np.asarray(response.magnitude).ravel()
    phase = np.degrees(np.unwrap(np.angle(np.asarray(response.complex).ravel())))
    result = {"gain_margin": math.inf, "gain_margin_dB": math.inf, "phase_margin_deg": math.inf,
              "gain_crossover_Hz": None, "phase_crossover_Hz": None}
    below = np.flatnonzero((magnitude[:-1] >= 1.0) & (magnitude[1:] < 1.0))
    if below.size:
        i = below[0]
        share = (magnitude[i] - 1.0) / (magnitude[i] - magnitude[i + 1])
        result["phase_margin_deg"] = float(180.0 + phase[i] + share * (phase[i + 1] - phase[i]))
        result["gain_crossover_Hz"] = float(omega[i] + share * (omega[i + 1] - omega[i])) / (2 * math.pi)
    tolerance = 1e-6    # [deg]: L(-1) is real, its phase -180 degrees to rounding
    crossing = np.flatnonzero((phase[:-1] > -180.0 + tolerance) & (phase[1:] <= -180.0 + tolerance))
    if crossing.size:
        i = crossing[0] + 1
        if phase[i] < -180.0 + tolerance and i > 0 and phase[i - 1] > -180.0:  # between grid points
            share = (phase[i - 1] + 180.0) / (phase[i - 1] - phase[i])
            gain = magnitude[i - 1] + share * (magnitude[i] - magnitude[i - 1])
            frequency = omega[i - 1] + share * (omega[i] - omega[i - 1])
        else:
            gain, frequency = magnitude[i], omega[i]
        result["gain_margin"] = float(1.0 / gain)
        result["gain_margin_dB"] = float(-20.0 * math.log10(gain))
        result["phase_crossover_Hz"] = float(frequency) / (2 * math.pi)
    return result


def loop_margins(scenario, Kp=None, Ki=None):
    """The operating point and :func:`stability_margins` of ``scenario``'s loop at gains Kp,
    Ki (default: the scenario's), JSON-ready."""
    controller = scenario.controller
    Kp = controller.Kp if Kp is None else Kp
    Ki = controller.Ki if Ki is None else Ki
    slope, temperature, load, direction = steepest_slope(scenario)
    margins = stability_margins(loop_transfer(Kp, Ki, slope, scenario.params, scenario.step_s),
                                scenario.step_s)
    return {"slope_ohm_per_K": slope, "T_degC": temperature, "load_kg": load,
            "direction": "heating" if direction == HEATING else "cooling", **margins}
