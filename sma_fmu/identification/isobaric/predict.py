"""``sma-fmu predict isobaric``: the plant runtime (the code the FMU runs) driven through a
lab file's measured temperature history at its stress, against the measured strain.

How the plant is driven: :class:`sma_fmu.runtime.plant.PlantStepper` takes electric power,
not temperature. Its thermal stage is made to follow the file's temperature exactly: a copy
of the parameters with the room temperature 50 K below the file's lowest reading and a
heat capacity 10^6 times smaller (a thermal time constant far below one step; every value
stays inside its plausible range), and
each step's power from :func:`sma_fmu.runtime.thermal.power_to_reach`. Everything after the
temperature, the branch switching, the minor-loop memory and the length with the
optional model terms, is the FMU's own code, in its default ("continuous") hysteresis mode.

The temperature fed is the file's temperature profile (the piecewise-linear curve the fit
also starts from, :mod:`~.profile`): thermocouple noise would otherwise make the plant
reverse at every sample and walk minor loops the wire never saw. ``--lag`` delays it by the
wire's first-order lag behind the thermocouple (the value ``fit isobaric`` reports; default
0: the FMU itself has no thermocouple). Two predicted strains are reported, and named:
from the model's own zero, length / reference length - 1 (the reference length and the
fitted phase lengths, nothing taken from the measured strain), and offset-matched, that
shifted by one constant, the median difference from the measured strain (a lab's strain
zero is its own; the fit gives each file its offset too).

The model's tangent temperatures (A_s, A_f, M_s, M_f) are taken on a clean sweep: the plant
runtime driven at the file's load through two full cycles, linear in temperature between
the file's lowest and highest (smoothed) reading, the second cycle's branches put through
the same tangent construction as the data. Drawn against the file's own noisy temperature
history, the predicted strain would inherit the thermocouple's scatter and the profile's
minor turns; the sweep is the model's own curve. The half-strain temperatures and the strain
span stay those of the file-driven prediction.
"""
import math
import time

import numpy as np

from sma_fmu.identification.isobaric.halfway import (half_strain_temperature,
                                                     transformation_strain)
from sma_fmu.identification.isobaric.lag import lagged
from sma_fmu.identification.isobaric.profile import temperature_profile
from sma_fmu.identification.isobaric.synthetic import stress_of_load
from sma_fmu.identification.transformation_temperatures import branch_tangents_or_reason
from sma_fmu.runtime.constants import HEATING
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.thermal import power_to_reach, step_decay

__all__ = ["drive_plant", "predict_file", "sweep_tangents", "TANGENT_KEYS"]

_ROOM_BELOW_K = 50.0
_CAPACITY_FACTOR = 1e6
TANGENT_KEYS = {HEATING: ("A_s", "A_f"), -HEATING: ("M_s", "M_f")}
SWEEP_POINTS = 2000


def drive_plant(params, temperature, load, step_s=1.0):
    """Wire length [m] per sample of the plant runtime following ``temperature`` [degC] at
    ``load`` [kg], one step of ``step_s`` [s] per sample, and the largest deviation [K] of
    the plant's temperature from the one asked for."""
    temperature = np.asarray(temperature, dtype=float)
    driven = params.replace(T_room=float(temperature.min()) - _ROOM_BELOW_K,
                            c_p=params.c_p / _CAPACITY_FACTOR,
                            T_max=max(params.T_max, float(temperature.max()) + 1.0))
    plant = PlantStepper(driven, T_start=float(temperature[0]), load=load)
    decay = step_decay(step_s, driven.tau_th)
    gain, room = driven.K_th, driven.T_room
    length = np.empty(temperature.size)
    reached = np.empty(temperature.size)
    length[0], reached[0] = plant.outputs.x, plant.outputs.T
    step = plant.step
    for i in range(1, temperature.size):
        out = step(power_to_reach(plant.temperature, temperature[i], room, gain, decay), load,
                   step_s)
        length[i], reached[i] = out.x, out.T
    return length, float(np.max(np.abs(reached - temperature)))


def sweep_tangents(params, load, low, high, points=SWEEP_POINTS):
    """({"A_s", "A_f", "M_s", "M_f"} [degC], {key: why} of the NaN ones) of the model at
    ``load`` [kg] on a clean sweep between ``low`` and ``high`` [degC]: two cycles of
    ``points`` samples a branch, the second cycle's branches."""
    up = np.linspace(low, high, points)
    sweep = np.concatenate([up, up[-2::-1], up[1:], up[-2::-1]])
    length, _ = drive_plant(params, sweep, load)
    strain = length / params.x0 - 1.0
    out, why = {}, {}
    for direction, rows in ((HEATING, slice(2 * points - 2, 3 * points - 2)),
                            (-HEATING, slice(3 * points - 3, 4 * points - 3))):
        tangents, reason = branch_tangents_or_reason(sweep[rows], strain[rows], direction)
        for key, name in zip(TANGENT_KEYS[direction], ("start", "finish")):
            out[key] = tangents[name] if tangents is not None else math.nan
            if tangents is None:
                why[key] = f"clean sweep {low:.4g} to {high:.4g} degC: {reason}"
    return out, why


def _tangents(temperature, strain, branches):
    """({"A_s", "A_f", "M_s", "M_f", "half_heating", "half_cooling" [degC],
    "transformation_strain" [1]}: medians over the complete branches, NaN where none gives
    one; {key: why} of the NaN ones)."""
    found = {key: [] for key in ("A_s", "A_f", "M_s", "M_f", "half_heating", "half_cooling",
                                 "transformation_strain")}
    why = {}
    for b in branches:
        if not b.complete:
            continue
        t, e = temperature[b.start:b.stop], strain[b.start:b.stop]
        tangents, reason = branch_tangents_or_reason(t, e, b.direction)
        start, finish = TANGENT_KEYS[b.direction]
        word = "heating" if b.direction == HEATING else "cooling"
        if tangents is not None:
            found[start].append(tangents["start"])
            found[finish].append(tangents["finish"])
        else:
            why.setdefault(start, f"{word}: {reason}")
            why.setdefault(finish, f"{word}: {reason}")
        found[f"half_{word}"].append(half_strain_temperature(t, e, b.direction))
        found["transformation_strain"].append(transformation_strain(t, e, b.direction))
        for key in (f"half_{word}", "transformation_strain"):
            why.setdefault(key, f"{word}: no half-strain crossing between the baselines")
    out = {}
    for key, values in found.items():
        values = [v for v in values if math.isfinite(v)]
        out[key] = float(np.median(values)) if values else math.nan
    return out, {key: why.get(key, "no complete branch of that direction")
                 for key, value in out.items() if not math.isfinite(value)}


def predict_file(data, params, lag=0.0):
    """{"predicted" [1], "measured" [1], "temperature" [degC], "report"} of one file;
    ``lag``: the wire's first-order lag behind the thermocouple [s, or samples without a
    time column] applied to the temperature fed (the fit's, from its report)."""
    began = time.perf_counter()
    window = data.splitting.window_samples if data.splitting is not None else 5
    profile = temperature_profile(data.temperature, data.branches, data.time, window).values
    step = float(np.median(np.diff(data.time))) if data.time is not None else 1.0
    profile = lagged(profile, lag, step)
    length, deviation = drive_plant(params, profile, data.load, step)
    raw = length / data.reference_length - 1.0
    offset = float(np.median(data.strain - raw))
    predicted = raw + offset
    residual = predicted - data.strain
    own_rms = float(np.sqrt(np.mean((raw - data.strain) ** 2)))
    seconds = time.perf_counter() - began
    measured_t, measured_why = _tangents(data.smoothed, data.strain, data.branches)
    model_t, model_why = _tangents(data.smoothed, predicted, data.branches)
    low, high = float(data.smoothed.min()), float(data.smoothed.max())
    swept, swept_why = sweep_tangents(params, data.load, low, high)
    model_t.update(swept)
    model_why = {k: v for k, v in model_why.items() if k not in swept} | swept_why
    report = {
        "experiment": "isobaric",
        "file": str(data.path), "points": int(data.strain.size), "load_kg": data.load,
        "stress_MPa": stress_of_load(data.load, params.diameter),
        "stress_column_MPa": data.stress_column,
        "columns": {q: list(v) for q, v in data.columns.items()},
        "strain_column_note": data.strain_note,
        "residual_rms": {"strain": float(np.sqrt(np.mean(residual ** 2))),
                         "strain_own_zero": own_rms},
        "strain_offset": offset,
        "reference_length_m": data.reference_length,
        "transformation_temperatures": {"measured": measured_t, "predicted": model_t,
                                        "predicted_minus_measured": {
                                            k: model_t[k] - measured_t[k] for k in model_t},
                                        "why_missing": {"measured": measured_why,
                                                        "predicted": model_why}},
        "drive": {"temperature": "the file's temperature profile (piecewise linear, knots by "
                                 "AIC), fed to the plant runtime sample by sample",
                  "step_s": step, "largest_temperature_deviation_K": deviation,
                  "lag": {"value": lag, "unit": "s" if data.time is not None else "samples"},
                  "hysteresis_mode": "continuous", "seconds": seconds,
                  "tangent_sweep_degC": [low, high]},
        "note": "residual_rms.strain: offset-matched, the prediction plant length / "
                "reference length - 1 shifted by strain_offset (the median difference from the "
                "measured strain; the plant has no residual-strain drift from cycle to cycle); "
                "residual_rms.strain_own_zero: the same prediction unshifted, from the model's "
                "own zero (reference_length_m and the fitted phase lengths); measured tangent-"
                "line and half-strain temperatures: the data against the measured (smoothed) "
                "temperature, medians over the branches; predicted A_s, A_f, M_s, M_f: the "
                "model on a clean sweep at the file's load over drive.tangent_sweep_degC; "
                "predicted half-strain temperatures: the offset-matched prediction against "
                "the measured (smoothed) temperature",
    }
    return {"predicted": predicted, "own_zero": raw, "measured": data.strain,
            "temperature": profile, "report": report}
