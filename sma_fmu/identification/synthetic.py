"""Synthetic measurement files from any parameter set, with chosen noise (seeded, reproducible).

Constant-load sweeps: for each load a heating sweep t_min -> t_max, then a cooling sweep
back from t_max - t_step to t_min, in steps of t_step; the sweeps cross the whole transformation, so the wire is on
its major branches. Constant-temperature cycles: the load follows straight lines between
the given loads, sampled every load_step.

Noise: Gaussian resistance noise [ohm] on each reading, and Gaussian temperature-sensor
noise [K] on the reported temperature (the wire's true temperature drives the model).
"""
import csv
import io
from pathlib import Path

import numpy as np

from sma_fmu.files.output_folder import write_file
from sma_fmu.runtime.checks import direction_name
from sma_fmu.runtime.constant_load import constant_load_resistance
from sma_fmu.runtime.constant_temperature import ConstantTemperatureModel
from sma_fmu.runtime.constants import COOLING, HEATING

__all__ = ["constant_load_rows", "constant_temperature_rows", "load_path", "write_rows"]


def _sweep(t_min, t_max, t_step):
    count = int(round((t_max - t_min) / t_step))
    if count < 2 or abs(t_min + count * t_step - t_max) > 1e-9 * max(1.0, abs(t_max)):
        raise ValueError(f"t_max - t_min = {t_max - t_min!r} K must be at least two whole steps "
                         f"of t_step = {t_step!r} K")
    return [t_min + i * t_step for i in range(count + 1)]


def constant_load_rows(params, loads, t_min=10.0, t_max=110.0, t_step=1.0, noise_ohm=0.0,
                       noise_K=0.0, seed=0, with_direction=True):
    """Rows (dicts) of a constant-load file: per load a heating then a cooling sweep [degC]."""
    rng = np.random.default_rng(seed)
    up = _sweep(t_min, t_max, t_step)
    rows = []
    for load in loads:
        for direction, temperatures in ((HEATING, up), (COOLING, up[-2::-1])):
            for t in temperatures:
                row = {
                    "temperature_C": t + noise_K * rng.standard_normal(),
                    "load_kg": load,
                    "resistance_ohm": constant_load_resistance(t, load, direction, params)
                    + noise_ohm * rng.standard_normal(),
                }
                if with_direction:
                    row["direction"] = direction_name(direction)
                rows.append(row)
    return rows


def load_path(loads, load_step):
    """Loads [kg] on straight lines between ``loads``, every ``load_step`` [kg] (ends included)."""
    path = [loads[0]]
    for start, end in zip(loads, loads[1:]):
        count = max(1, int(np.ceil(abs(end - start) / load_step - 1e-9)))
        path.extend(start + (end - start) * i / count for i in range(1, count + 1))
    return path


def constant_temperature_rows(params, temperature, loads, load_step=0.005, noise_ohm=0.0,
                              noise_K=0.0, seed=0):
    """Rows (dicts) of a constant-temperature file: the load cycled through ``loads`` [kg]."""
    rng = np.random.default_rng(seed)
    model = ConstantTemperatureModel(temperature, params)
    rows = []
    for load in load_path(loads, load_step):
        resistance = model.resistance_sequence([load])[0]
        rows.append({"load_kg": load,
                     "resistance_ohm": resistance + noise_ohm * rng.standard_normal(),
                     "temperature_C": temperature + noise_K * rng.standard_normal()})
    return rows


def write_rows(path, rows):
    """Write rows (dicts with the same keys) as CSV; numbers exactly (shortest round-trip repr).

    The file is written whole or not at all (temporary file, then a rename).
    """
    stream = io.StringIO(newline="")
    writer = csv.DictWriter(stream, fieldnames=list(rows[0]))
    writer.writeheader()
    for row in rows:
        writer.writerow({k: (repr(float(v)) if isinstance(v, float) else v) for k, v in row.items()})
    write_file(path, stream.getvalue())
    return Path(path)
