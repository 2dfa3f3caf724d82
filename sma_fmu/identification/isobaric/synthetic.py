"""Synthetic isobaric thermal-cycling files (ASTM E3097-style), seeded and reproducible.

The wire hangs at a constant load while a furnace runs a temperature programme: a dwell at
``t_low``, a ramp at ``rate`` up to ``t_high``, a dwell, a ramp down, a dwell, ``cycles``
times. The thermocouple reads the programme; the wire follows it with a first-order lag of
time constant ``lag_s`` [s] (:mod:`sma_fmu.identification.isobaric.lag`; 0: no lag). The
wire's temperature drives the model (major branches, spec section 4; the direction is that
of the wire's temperature, which turns after the thermocouple's, kept through each dwell),
so with a lag a transformation that ends near the top goes on after the measured
temperature has turned. The file reports:

- the thermocouple temperature with Gaussian noise ``noise_K`` [K] (so it is not monotone
  within a branch),
- strain relative to the reference length (x / L_ref - 1) with Gaussian noise
  ``noise_strain`` [1], in percent, as a fraction, or as a length [m],
- a residual strain that grows during each cooling transformation, in proportion to the
  transformed share q = xi_MF/M: cycle k leaves ``residual * decay**k`` behind (the
  training drift of a fresh wire), so each cycle's loop is open by that amount,
- optionally time [s] and resistance [ohm] with noise ``noise_ohm``,
- optionally a first cycle unlike the rest: its transformation ``first_shift_K`` [K] hotter
  (a fresh wire's first cycle).

With ``rates`` each cycle ramps at its own rate, in turn: cycles that cross their
transformation at different rates are what tells a lag from a wider hysteresis
(:mod:`~.sensor`). A header of ``#`` lines states the load, the programme, the noise and
the true drift.
A lab-like file: ``IsobaricProgramme(t_low=20, t_high=115, rate=20, cycles=100,
dwell=0, points=26000, noise_K=10, lag_s=20, decay=0.97)`` written without a time column:
100 cycles of 260 samples, the heating transformation finishing after the measured turn.
"""
import math
from dataclasses import dataclass

import numpy as np

from sma_fmu.identification.isobaric.lag import lagged
from sma_fmu.identification.isobaric.terms import branch_curve
from sma_fmu.runtime.constants import COOLING, HEATING, STANDARD_GRAVITY

__all__ = ["IsobaricProgramme", "temperature_programme", "wire_temperature", "isobaric_table", "isobaric_text",
           "stress_of_load", "load_of_stress", "STRAIN_UNITS"]

STRAIN_UNITS = ("percent", "fraction", "length")
_COLUMN = {"percent": "strain_percent", "fraction": "strain", "length": "length_m"}


def stress_of_load(load, diameter):
    """Tensile stress [MPa] of a hung mass ``load`` [kg] on a wire of ``diameter`` [m]."""
    return STANDARD_GRAVITY * load / (math.pi * diameter ** 2 / 4.0) / 1e6


def load_of_stress(stress, diameter):
    """Hung mass [kg] that stresses a wire of ``diameter`` [m] to ``stress`` [MPa]."""
    return stress * 1e6 * (math.pi * diameter ** 2 / 4.0) / STANDARD_GRAVITY


@dataclass(frozen=True)
class IsobaricProgramme:
    """A synthetic test: temperature programme, sampling, noise and drift (units in names)."""

    t_low: float = 15.0            # degC
    t_high: float = 130.0          # degC
    rate: float = 10.0             # K/min
    cycles: int = 3
    dwell: float = 60.0            # s at each end
    points: int = 3000             # samples in the file, evenly spaced in time
    noise_K: float = 3.0
    noise_strain: float = 1e-4
    noise_ohm: float = 0.05
    residual: float = 1.5e-3       # residual strain of the first cycle [1]
    decay: float = 0.5             # ratio of one cycle's residual strain to the previous
    seed: int = 0
    lag_s: float = 0.0             # time constant of the wire behind the thermocouple [s]
    first_shift_K: float = 0.0     # the first cycle's transformation this much hotter [K]
    rates: tuple = ()              # K/min of each cycle in turn (repeated); () = ``rate``

    def __post_init__(self):
        if not self.t_high > self.t_low:
            raise ValueError(f"t_high = {self.t_high!r} degC must exceed t_low = {self.t_low!r} degC")
        if self.cycles < 1 or self.points < 20 * self.cycles:
            raise ValueError(f"cycles = {self.cycles!r} and points = {self.points!r}: need at least "
                             f"one cycle and 20 points per cycle")
        for value in (self.rate,) + tuple(self.rates):
            if not value > 0:
                raise ValueError(f"rate = {value!r} K/min must be > 0")
        for name in ("dwell", "noise_K", "noise_strain", "noise_ohm", "residual", "decay", "lag_s",
                     "first_shift_K"):
            if not getattr(self, name) >= 0:
                raise ValueError(f"{name} = {getattr(self, name)!r} must be >= 0")


def wire_temperature(programme):
    """(time [s], measured temperature without noise [degC], wire temperature [degC], wire
    direction +1/-1, cycle index from 0) of the programme with the wire's lag."""
    time, measured, direction, cycle = temperature_programme(programme)
    if not programme.lag_s > 0:
        return time, measured, measured, direction, cycle
    step = float(time[1] - time[0])
    wire = lagged(measured, programme.lag_s, step)
    # the wire heats while the thermocouple reads more than the wire (dw/dt = (u - w)/tau)
    gap = measured - wire
    direction = np.where(gap > 1e-9, HEATING, np.where(gap < -1e-9, COOLING, 0))
    direction[0] = direction[0] or HEATING
    for i in np.nonzero(direction == 0)[0]:
        direction[i] = direction[i - 1]
    starts = np.concatenate([[0], (np.diff(direction) > 0).astype(int)])
    cycle = np.clip(np.cumsum(starts), 0, programme.cycles - 1)
    return time, measured, wire, direction, cycle


def _varying_programme(programme):
    """:func:`temperature_programme` with each cycle's ramps at its own rate (``rates``)."""
    p = programme
    times, values, cycle_of = [0.0, p.dwell], [p.t_low, p.t_low], [0, 0]
    for k in range(p.cycles):
        ramp = (p.t_high - p.t_low) / p.rates[k % len(p.rates)] * 60.0
        for step, value in ((ramp, p.t_high), (p.dwell, p.t_high), (ramp, p.t_low),
                            (p.dwell, p.t_low)):
            times.append(times[-1] + step)
            values.append(value)
            cycle_of.append(k)
    times, values = np.array(times), np.array(values)
    time = np.linspace(0.0, times[-1], p.points)
    temperature = np.interp(time, times, values)
    segment = np.clip(np.searchsorted(times, time, side="right") - 1, 0, times.size - 2)
    # segments after the first dwell come in fours: up, top dwell, down, bottom dwell
    direction = np.where((segment == 0) | ((segment - 1) % 4 < 2), HEATING, COOLING)
    cycle = np.clip((segment - 1) // 4, 0, p.cycles - 1)
    return time, temperature, direction, cycle


def temperature_programme(programme):
    """(time [s], true temperature [degC], direction +1/-1, cycle index) of the programme."""
    if programme.rates:
        return _varying_programme(programme)
    ramp = (programme.t_high - programme.t_low) / programme.rate * 60.0
    period = 2.0 * (ramp + programme.dwell)
    total = programme.dwell + programme.cycles * period
    time = np.linspace(0.0, total, programme.points)
    phase = time - programme.dwell
    cycle = np.clip(np.floor(phase / period), 0, programme.cycles - 1).astype(int)
    local = phase - cycle * period
    span = programme.t_high - programme.t_low
    temperature = np.where(
        local < 0.0, programme.t_low, np.where(
            local < ramp, programme.t_low + span * local / max(ramp, 1e-300), np.where(
                local < ramp + programme.dwell, programme.t_high, np.where(
                    local < 2.0 * ramp + programme.dwell,
                    programme.t_high - span * (local - ramp - programme.dwell) / max(ramp, 1e-300),
                    programme.t_low))))
    direction = np.where((local >= 0.0) & (local < ramp + programme.dwell), HEATING, COOLING)
    direction[phase < 0.0] = HEATING
    return time, temperature, direction, cycle


def isobaric_table(params, load, programme, strain_unit="percent", with_time=True,
                   with_resistance=False, reference_length=None):
    """The columns of a synthetic file: {name: array}, plus the true offsets per level.

    ``load`` [kg]; ``reference_length`` [m] defaults to the wire's x0.
    Returns (columns, truth) with truth = {"offsets": strain offset of each level [1],
    "true_temperature": the wire's [degC], "lag_samples": lag_s over the sample step}.
    """
    if strain_unit not in STRAIN_UNITS:
        raise ValueError(f"strain unit must be one of {', '.join(STRAIN_UNITS)}, got {strain_unit!r}")
    reference = params.x0 if reference_length is None else reference_length
    rng = np.random.default_rng(programme.seed)
    time, measured_t, true_t, direction, cycle = wire_temperature(programme)
    strain = np.empty(time.size)
    resistance = np.empty(time.size)
    offsets = np.concatenate([[0.0], np.cumsum(programme.residual
                                               * programme.decay ** np.arange(programme.cycles))])
    for d in (HEATING, COOLING):
        rows = direction == d
        shift = np.where(cycle[rows] == 0, programme.first_shift_K, 0.0)
        model, ohm, share = branch_curve(true_t[rows] - shift, load, d, params, reference)
        drift = offsets[cycle[rows]]
        if d == COOLING:
            drift = drift + (offsets[cycle[rows] + 1] - offsets[cycle[rows]]) * share
        strain[rows] = model + drift
        resistance[rows] = ohm
    columns = {}
    if with_time:
        columns["time_s"] = time
    columns["temperature_C"] = measured_t + programme.noise_K * rng.standard_normal(time.size)
    measured = strain + programme.noise_strain * rng.standard_normal(time.size)
    columns[_COLUMN[strain_unit]] = {"percent": 100.0 * measured, "fraction": measured,
                                     "length": reference * (1.0 + measured)}[strain_unit]
    noise_r = programme.noise_ohm * rng.standard_normal(time.size)
    if with_resistance:
        columns["resistance_ohm"] = resistance + noise_r
    return columns, {"offsets": offsets.tolist(), "true_temperature": true_t,
                     "lag_samples": programme.lag_s / float(time[1] - time[0])}


_DIGITS = {"time_s": 3, "temperature_C": 3, "strain_percent": 6, "strain": 8, "length_m": 9,
           "resistance_ohm": 4}


def isobaric_text(columns, header_lines):
    """CSV text: ``#`` header lines, a column row, then the rows (fixed decimals per column)."""
    names = list(columns)
    formats = [f"{{:.{_DIGITS[name]}f}}" for name in names]
    lines = [f"# {line}" for line in header_lines] + [",".join(names)]
    for values in zip(*(columns[name] for name in names)):
        lines.append(",".join(fmt.format(v) for fmt, v in zip(formats, values)))
    return "\n".join(lines) + "\n"
