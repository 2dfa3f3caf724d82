"""Unknowns of the isobaric fit: where each lives in the vector, and its starting value.

Columns: the physical parameters, the strain offsets of every file, the lag of every file
(when fitted), then every file's temperature-profile knots. Starting values are estimated
from the data: centres and widths from the branches' half-way crossings on the
temperature-only profile (lagged by the starting lag), levels from the strain.
"""
import math

import numpy as np

from sma_fmu.identification.isobaric.jacobian import file_model
from sma_fmu.identification.isobaric.lag import lagged
from sma_fmu.identification.isobaric.profile import wire_rows
from sma_fmu.identification.measurements import MeasurementError
from sma_fmu.runtime.constant_load import residual_f_fraction
from sma_fmu.runtime.constants import BOLTZMANN, COOLING, HEATING, KELVIN_OFFSET, STANDARD_GRAVITY
from sma_fmu.runtime.parameters import ParameterError

__all__ = ["Layout", "starts"]


class Layout:
    """Columns of the unknowns, and their map onto the wire parameters."""

    def __init__(self, files, base, fit_slopes, absolute, with_resistance, fit_lag):
        self.phys = ["a_h"] + (["b_h"] if fit_slopes else []) + ["a_c"] + \
            (["b_c"] if fit_slopes else []) + ["nu", "l_MF"] + (["x_min"] if absolute else []) + \
            (["R_P", "R_MF"] if with_resistance else [])
        self.offsets = []   # per file: (first column, count, level-0 fixed at zero)
        names = list(self.phys)
        for f in files:
            count = f.data.levels if f.per_cycle else 1
            fixed = f.data.absolute
            self.offsets.append((len(names), count - fixed, fixed))
            names += [f"offset_{f.index}_{level}" for level in range(fixed, count)]
        self.lags = []
        for f in files:
            self.lags.append(len(names) if fit_lag else None)
            names += [f"lag_{f.index}"] if fit_lag else []
        self.reported = names
        self.knots = []
        column = len(names)
        for f in files:
            self.knots.append(slice(column, column + f.profile.knot_count))
            column += f.profile.knot_count
        self.size = column
        self.base = base
        self.paths = ", ".join(str(f.data.path) for f in files)
        self.half_l = 0.5 * (base.l_F - base.l_M)
        self.half_r = 0.5 * (base.R_F - base.R_M)

    def params(self, vector):
        """WireParameters of ``vector``; a non-finite or invalid value names the data files."""
        values = dict(zip(self.phys, vector[:len(self.phys)].tolist()))
        bad = [f"{k} = {v!r}" for k, v in values.items() if not math.isfinite(v)]
        if bad:
            raise MeasurementError(f"{self.paths}: the fit produced a non-finite parameter "
                                   f"({', '.join(bad)}); the data do not determine it")
        changes = {k: v for k, v in values.items() if k not in ("l_MF", "R_MF")}
        changes["l_M"], changes["l_F"] = values["l_MF"] - self.half_l, values["l_MF"] + self.half_l
        if "R_MF" in values:
            changes["R_M"] = values["R_MF"] - self.half_r
            changes["R_F"] = values["R_MF"] + self.half_r
        try:
            return self.base.replace(**changes)
        except ParameterError as error:
            detail = str(error).split(": ", 1)[-1]
            raise MeasurementError(f"{self.paths}: the fit reached an invalid parameter "
                                   f"({detail})") from None

    def time_order(self, files):
        """Column order for the sparse solves: every file's offsets and knots by the sample
        where they act, file after file, then the physical unknowns and the lags."""
        key = np.full(self.size, np.inf)
        for f in files:
            base = f.index * (f.data.temperature.size + 1.0)
            key[self.knots[f.index]] = base + f.profile.knots
            first, count, fixed = self.offsets[f.index]
            starts = {}
            for b in f.data.branches:
                starts.setdefault(b.level if f.per_cycle else 0, b.start)
            for level in range(fixed, count + fixed):
                key[first + level - fixed] = base + starts.get(level, f.data.temperature.size)
        return np.argsort(key, kind="stable")

    def levels(self, vector, index):
        first, count, fixed = self.offsets[index]
        return np.concatenate([[0.0] * fixed, vector[first:first + count]])


def _crossings(f, temperature):
    """Per direction: (centre [degC], 25-75 % width [K], span, cold, hot) of complete branches."""
    out = {HEATING: [], COOLING: []}
    for b in f.data.branches:
        if not b.complete:
            continue
        t, e = temperature[b.start:b.stop], f.data.strain[b.start:b.stop]
        order = np.argsort(t)
        t, e = t[order], e[order]
        ends = max(3, t.size // 10)
        cold, hot = np.median(e[:ends]), np.median(e[-ends:])
        share = (e - hot) / (cold - hot) if cold != hot else np.zeros_like(e)
        marks = []
        for target in (0.75, 0.5, 0.25):
            near = np.abs(share - target) <= 0.1
            marks.append(float(np.median(t[near])) if near.any() else math.nan)
        out[b.direction].append((marks[1], abs(marks[2] - marks[0]), cold - hot, cold, hot))
    return out


def starts(files, layout, base, lag_fraction=0.01):
    """Starting vector and bounds, estimated from the data; with a lag column the lag starts
    at ``lag_fraction`` of a cycle and the crossings are read on the profile lagged by it."""
    vector = np.zeros(layout.size)
    lower = np.full(layout.size, -np.inf)
    upper = np.full(layout.size, np.inf)
    centres = {HEATING: [], COOLING: []}
    widths, spans, r_levels = [], [], []
    for f in files:
        vector[layout.knots[f.index]] = f.profile.factor.solve(f.profile.basis.T @ f.data.temperature)
        lower[layout.knots[f.index]] = -KELVIN_OFFSET + 1.0
        profile = f.profile.values
        if layout.lags[f.index] is not None:
            period = f.data.splitting.period_samples * f.step if f.data.splitting else 100 * f.step
            vector[layout.lags[f.index]] = lag_fraction * period
            lower[layout.lags[f.index]], upper[layout.lags[f.index]] = 0.0, period / 4.0
            profile = lagged(profile, lag_fraction * period, f.step)
        marks = _crossings(f, profile)
        for d in (HEATING, COOLING):
            for centre, width, span, cold, hot in marks[d]:
                if math.isfinite(centre):
                    centres[d].append((f.data.load, centre))
                if math.isfinite(width) and width > 0:
                    widths.append((centre + KELVIN_OFFSET, width, f.data.load))
                spans.append((f.data, span, cold, hot))
        if f.data.resistance is not None:
            low, high = np.quantile(profile, [0.1, 0.9])
            r_levels.append((f.data, float(np.median(f.data.resistance[profile >= high])),
                             float(np.median(f.data.resistance[profile <= low]))))
    for d in (HEATING, COOLING):
        if not centres[d]:
            raise MeasurementError(f"{layout.paths}: no complete "
                                   f"{'heating' if d == HEATING else 'cooling'} branch crosses "
                                   f"the transformation")
    start = {}
    for d, a, b in ((HEATING, "a_h", "b_h"), (COOLING, "a_c", "b_c")):
        f_, tau = np.array(centres[d]).T
        if b in layout.phys:
            slope, intercept = np.polyfit(f_, tau, 1)
            start[a], start[b] = float(intercept), float(slope)
        else:
            start[a] = float(np.mean(tau - getattr(base, b) * f_))
    # the 25-75 % width of the logistic is 2 ln 3 k_B T^2 / dH
    if widths:
        energy = np.median([2.0 * math.log(3.0) * BOLTZMANN * t * t / w for t, w, _ in widths])
        per_nu = base.eps_T - STANDARD_GRAVITY * float(np.median([f_ for _, _, f_ in widths])) \
            * base.x_T / base.N
        start["nu"] = float(energy / per_nu)
    if not (widths and math.isfinite(start["nu"]) and start["nu"] > 0):
        start["nu"] = base.nu   # no branch resolves its 25-75 % width: the base file's
    span = float(np.median([s for _, s, _, _ in spans]))
    if not span > 0:
        raise MeasurementError(f"{layout.paths}: the strain is lower when cold than when hot; "
                               f"the model needs the wire to contract on heating (actuation "
                               f"strain > 0)")
    data0 = spans[0][0]
    xi_f_min = residual_f_fraction(data0.load, base)
    reference = data0.reference_length
    if "x_min" in layout.phys:
        cold_length = reference * (1 + float(np.median([c for _, _, c, _ in spans])))
        hot_length = reference * (1 + float(np.median([h for _, _, _, h in spans])))
        start["l_MF"] = cold_length - xi_f_min * layout.half_l
        start["x_min"] = (hot_length - xi_f_min * (start["l_MF"] + layout.half_l)) / (1 - xi_f_min)
    else:
        start["l_MF"] = base.x_min + span * reference / (1.0 - xi_f_min)
    if r_levels:
        data, r_hot, r_cold = r_levels[0]
        xi = residual_f_fraction(data.load, base)
        start["R_MF"] = r_cold - xi * layout.half_r
        start["R_P"] = (r_hot - xi * (start["R_MF"] + layout.half_r)) / (1.0 - xi)
    x_min = start.get("x_min", base.x_min)
    bounds = {"a_h": (-100.0, 400.0), "a_c": (-100.0, 400.0), "b_h": (-5000.0, 5000.0),
              "b_c": (-5000.0, 5000.0), "nu": (1e-3 * start["nu"], 1e3 * start["nu"]),
              "l_MF": (x_min * (1 + 1e-9), 2.0 * x_min), "x_min": (0.5 * x_min, 2.0 * x_min),
              "R_P": (1e-3, start.get("R_MF", 1.0)), "R_MF": (start.get("R_P", 1.0), 1e4)}
    k = len(layout.phys)
    for i, name in enumerate(layout.phys):
        vector[i] = start[name]
        lower[i], upper[i] = bounds[name]
    vector[:k] = np.clip(vector[:k], lower[:k] + 1e-12, upper[:k] - 1e-12)
    params = layout.params(vector)
    for f in files:
        first, count, fixed = layout.offsets[f.index]
        direction, level, _ = wire_rows(f.profile.values, f.data.branches, f.per_cycle)
        strain, _ = file_model(params, f.data, f.profile.values, np.zeros(count + fixed),
                               direction, level, f.per_cycle)
        difference = f.data.strain - strain
        for lv in range(fixed, count + fixed):
            rows = level == lv
            vector[first + lv - fixed] = float(np.median(difference[rows])) if rows.any() else 0.0
    return vector, lower, upper
