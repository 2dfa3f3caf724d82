"""Starting values and bounds of the isobaric fit's unknowns, estimated from the data.

Centres and widths come from the branches' half-way and 25/75 % crossings on the
temperature-only profile (lagged by the starting lag), the stress law from the spans of the
files, the levels from the strain. A second stage starts as a broader copy of the first
(same centres, a third of the domain size) holding a fifth of the transformation.

The temperature profile's knots are bounded: each stays within PROFILE_BOUND standard errors
of the thermocouple profile at that knot (the measured temperature's own least-squares fit on
the knots Akaike's criterion chose from it alone; the standard error from the thermocouple
noise, :func:`~.profile.pointwise_error`), or within PROFILE_TOLERANCE_K where that is wider
(a filtered file's noise estimate is the filter's remains, and no thermocouple is that exact:
2.5 K is the class-2 tolerance of IEC 60584, the usual grade of a lab's thermocouple). Inside
that band the temperature residual weighs every move; beyond it a move cannot be thermocouple
noise (5 sigma: about one knot in a million by chance), so a wire temperature the strain would
want further away is the model not following the data, and shows as strain residual instead
of a profile bent by tens of kelvin (on the shared raw file, 40 K at the bottom turns without
the bound). The band is not taken from the temperature's fit on the joint profile's own knots:
with a knot wherever the strain is steep, a few samples apart, each such knot's standard error
is near the noise itself, and a run of them moved together by up to 5 sigma each (the raw
file's cooling ends, 4 K of noise: the wire 6 to 10 K above the thermocouple over the last 20
samples of cycles 2 to 26).
"""
import math

import numpy as np

from sma_fmu.identification.isobaric.jacobian import file_model
from sma_fmu.identification.isobaric.lag import lagged
from sma_fmu.identification.isobaric.profile import wire_rows
from sma_fmu.identification.isobaric.terms import stress_MPa
from sma_fmu.identification.measurements import MeasurementError
from sma_fmu.runtime.constant_load import residual_f_fraction
from sma_fmu.runtime.constants import BOLTZMANN, COOLING, HEATING, KELVIN_OFFSET, STANDARD_GRAVITY
from sma_fmu.runtime.model_terms import domain_widths

__all__ = ["starts", "LAG_LIMIT", "BOUNDS", "PROFILE_BOUND", "PROFILE_TOLERANCE_K"]

LAG_LIMIT = 1 / 20       # of a cycle: the largest lag the fit may reach (the lag guard)
PROFILE_BOUND = 5.0      # standard errors the profile's knots may move from the temperature's fit
PROFILE_TOLERANCE_K = 2.5   # or this far where larger: IEC 60584 class-2 thermocouple tolerance
BOUNDS = {"w2": (0.0, 0.95), "alpha_P": (-2e-3, 2e-3),
          "alpha_MF": (-2e-3, 2e-3), "span_ratio_0": (0.01, 10.0), "span_stress": (1.0, 5000.0)}


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


def _centre_lines(centres, layout, base):
    """{"h": (intercept, slope), "c": ...} of the half-way crossings against load: a straight
    line with two loads or more, else the centre at the one load (the base file's slope)."""
    line = {}
    for d, key, b in ((HEATING, "h", "b_h"), (COOLING, "c", "b_c")):
        f_, tau = np.array(centres[d]).T
        if layout.fit_slopes and np.ptp(f_) > 0:
            slope, intercept = np.polyfit(f_, tau, 1)
        else:
            slope = getattr(base, b)
            intercept = float(np.mean(tau - slope * f_))
        line[key] = (float(intercept), float(slope))
    return line


def _energy_starts(widths, base):
    """nu_h, nu_c from the 25-75 % widths, 2 ln 3 k_B T^2 / dH, per direction."""
    out = {}
    for d, name in ((HEATING, "nu_h"), (COOLING, "nu_c")):
        mine = [w for w in widths if w[3] == d] or widths
        if not mine:
            out[name] = base.nu
            continue
        energy = np.median([2.0 * math.log(3.0) * BOLTZMANN * t * t / w for t, w, _, _ in mine])
        per_nu = base.eps_T - STANDARD_GRAVITY * float(np.median([f_ for _, _, f_, _ in mine])) \
            * base.x_T / base.N
        value = float(energy / per_nu)
        out[name] = value if math.isfinite(value) and value > 0 else base.nu
    return out


def _span_law(spans, diameter):
    """(span_ratio_0, span_stress [MPa], saturated span [1]) of s = 1 + (s0 - 1) e^(-sigma/S)
    through the files' spans (a coarse grid search; the fit refines it)."""
    stress = np.array([stress_MPa(d.load, diameter) for d, *_ in spans], dtype=float)
    span = np.array([s for _, s, _, _ in spans])
    best = None
    for s0 in np.linspace(0.05, 1.5, 30):
        for scale in np.geomspace(20.0, 2000.0, 30):
            shape = 1.0 + (s0 - 1.0) * np.exp(-stress / scale)
            top = float(shape @ span / (shape @ shape))
            cost = float(np.sum((top * shape - span) ** 2))
            if best is None or cost < best[0]:
                best = (cost, s0, scale, top)
    return best[1], best[2], best[3]


def starts(files, layout, base, lag_fraction=0.01):
    """Starting vector and bounds, estimated from the data; with a lag column the lag starts
    at ``lag_fraction`` of a cycle (at most LAG_LIMIT, its bound) and the crossings are read
    on the profile lagged by it."""
    vector = np.zeros(layout.size)
    lower = np.full(layout.size, -np.inf)
    upper = np.full(layout.size, np.inf)
    centres = {HEATING: [], COOLING: []}
    widths, spans, r_levels = [], [], []
    for f in files:
        # the knots stay within PROFILE_BOUND standard errors of the thermocouple profile
        # (the temperature's own fit, its knots chosen by AIC) and start on it
        knots = layout.knots[f.index]
        own = f.thermocouple.values[f.profile.knots]
        error = PROFILE_BOUND * f.tc_error[f.profile.knots]
        lower[knots] = np.maximum(own - error, -KELVIN_OFFSET + 1.0)
        upper[knots] = own + error
        vector[knots] = own
        profile = f.thermocouple.values
        if layout.lags[f.index] is not None:
            period = f.data.splitting.period_samples * f.step if f.data.splitting else 100 * f.step
            lag = min(lag_fraction, LAG_LIMIT) * period
            vector[layout.lags[f.index]] = lag
            lower[layout.lags[f.index]], upper[layout.lags[f.index]] = 0.0, LAG_LIMIT * period
            profile = lagged(profile, lag, f.step)
        marks = _crossings(f, profile)
        for d in (HEATING, COOLING):
            for centre, width, span, cold, hot in marks[d]:
                if math.isfinite(centre):
                    centres[d].append((f.data.load, centre))
                if math.isfinite(width) and width > 0:
                    widths.append((centre + KELVIN_OFFSET, width, f.data.load, d))
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
    lines = _centre_lines(centres, layout, base)
    start = {}
    for law in layout.centres:    # the second stage starts on the first one's centres
        start.update(law.start(lines))
    start.update(domain_widths(_energy_starts(widths, base)))
    span = float(np.median([s for _, s, _, _ in spans]))
    if not span > 0:
        raise MeasurementError(f"{layout.paths}: the strain is lower when cold than when hot; "
                               f"the model needs the wire to contract on heating (actuation "
                               f"strain > 0)")
    start["span_ratio_0"], start["span_stress"] = base.terms.span_ratio_0, base.terms.span_stress
    if "span_ratio_0" in layout.phys:
        s0, scale, span = _span_law(spans, base.diameter)   # span: the saturated one
        start["span_ratio_0"] = s0
        if "span_stress" in layout.phys:
            start["span_stress"] = scale
    start["alpha_P"] = start["alpha_MF"] = 0.0
    start.update({"w2": 0.2, "nu2_h": start["nu_h"] / 3.0, "nu2_c": start["nu_c"] / 3.0})
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
    bounds = dict(BOUNDS, **{name: law.bounds(name) for law in layout.centres
                             for name in law.names}, **{
        "l_MF": (x_min * (1 + 1e-9), 2.0 * x_min), "x_min": (0.5 * x_min, 2.0 * x_min),
        "R_P": (1e-3, start.get("R_MF", 1.0)), "R_MF": (start.get("R_P", 1.0), 1e4)})
    for name in ("nu", "nu_h", "nu_c", "nu2_h", "nu2_c"):
        bounds[name] = (1e-3 * start[name], 1e3 * start[name])
    k = len(layout.phys)
    for i, name in enumerate(layout.phys):
        vector[i] = start[name]
        lower[i], upper[i] = bounds[name]
    vector[:k] = np.clip(vector[:k], lower[:k] + 1e-12, upper[:k] - 1e-12)
    params = layout.params(vector)
    for f in files:
        first, count, fixed = layout.offsets[f.index]
        direction, level, _ = wire_rows(f.thermocouple.values, f.data.branches, f.per_cycle)
        strain, _ = file_model(params, f.data, f.thermocouple.values, np.zeros(count + fixed),
                               direction, level, f.per_cycle)
        difference = f.data.strain - strain
        previous = 0.0
        for lv in range(fixed, count + fixed):
            rows = level == lv      # a level no row sits on (after the last cooling): as before
            previous = float(np.median(difference[rows])) if rows.any() else previous
            vector[first + lv - fixed] = previous
    return vector, lower, upper
