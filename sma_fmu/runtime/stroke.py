"""Stroke control by self-sensing: a stroke reference [m] mapped to a resistance reference R_ref
[ohm] through the model, so the controller still feeds back the wire's resistance.

The stroke is the contraction s = x_0 - x from the wire's length x_0 at the start of the run
(what a run records as ``stroke``). On a branch at load f, with xi_MF the mixed fraction,

    xi_P = M - xi_MF,  xi_M = xi_MF/2,  xi_F = xi_Fmin + xi_MF/2          (M = 1 - xi_Fmin(f))
    R    = R_P xi_P + R_M xi_M + R_F xi_F                                  no temperature in it
    x    = l_P xi_P + l_M xi_M + l_F xi_F     (strain terms: stressed lengths, and with thermal
                                               expansion factors of the temperature T)

so at one temperature both are affine in xi_MF. **The method:** without thermal expansion x
does not depend on T, and xi_MF = M (x* - x(0)) / (x(M) - x(0)) for the target length
x* = x_0 - s is closed form; R_ref follows on the same line. With thermal expansion
(alpha_P or alpha_MF != 0) the temperature that goes with xi_MF is the branch's own: the map
finds the root of F(T) = T'(T) - T, where T' is the major branch's inverse
(:func:`~.sensing.temperature_of_fractions`: closed form, or the two-stage Newton search of
:mod:`.two_stage_root`) at the xi_MF the affine solve gives at T. The root lies between the
temperatures of the branch's two ends (T' never leaves them, so F changes sign there). From
the branch's centre: one fixed-point step (T <- T'), then secant steps through the last two
residuals, the bracket narrowed by each residual's sign; a step that would leave it halves it
instead, as the two-stage search does (near saturation the fixed point alone jumps between the
ends). Stopped when |F| <= :data:`~.two_stage_root.ROOT_TOLERANCE_K`; at most
:data:`~.two_stage_root.ROOT_CAP` rounds. Every step depends on the asked stroke and load
only, not on earlier calls, so the map is a function.

The branch is the major branch of ``direction`` (the sign of the stroke reference's last
change: a rising stroke heats). On a minor branch the wire holds the same (R, xi_MF) pairs;
only the thermal expansion's T differs, by less than the hysteresis width.

**Reach:** xi_MF is clamped into [delta, M - delta], delta = saturation_margin M, as the
temperature-sensing inverse clamps it: a stroke beyond what the wire gives at that load (more
than all of M transformed to P, or less than none) maps to the end's R_ref, and the target
says ``clamped`` and the stroke it does give.

**Cost per step:** the last target is kept, so a reference and load held over a step cost one
comparison; a new (stroke, load, direction) costs one affine solve and one branch inverse
without thermal expansion, else a handful of rounds of one each (``sma-fmu bench --only
stroke`` measures the cost and counts the rounds).
"""
from collections import namedtuple

from .constant_load import BranchCache
from .constants import HEATING
from .phases import resistance_of
from .plant import PlantStepper, branch_length
from .sensing import temperature_of_fractions
from .two_stage_root import ROOT_CAP, ROOT_TOLERANCE_K

__all__ = ["StrokeTarget", "StrokeMap", "StrokeReference", "step_table", "start_length"]

StrokeTarget = namedtuple("StrokeTarget", ["R_ref", "stroke", "temperature", "clamped"])
StrokeTarget.__doc__ = """Where the wire gives a stroke on a branch at one load.

R_ref : the resistance there [ohm]; stroke : the stroke it gives [m] (the asked one unless
clamped); temperature : the branch's temperature there [degC]; clamped : the asked stroke
lay beyond the reach at that load (see the module docstring).
"""


def step_table(step_s, values):
    """``values`` [ohm] at t_k = k ``step_s`` [s], k = 0, 1, ..., as a ``[reference]`` table:
    the knots inside a run of equal values left out (a table interpolates them back)."""
    last = len(values) - 1
    inner = [k for k, (before, value, after) in enumerate(zip(values, values[1:], values[2:]), 1)
             if not before == value == after]
    kept = [0, *inner, last] if last > 0 else [0]
    return {"kind": "table", "times_s": [k * step_s for k in kept],
            "values_ohm": [values[k] for k in kept]}


def start_length(params, T_start, load):
    """x_0 [m]: the plant's length at the start (``T_start`` [degC], ``load`` [kg]), as the
    plant computes it, so that stroke 0 is the run's first sample."""
    return PlantStepper(params, T_start, "switch", load).outputs.x


class StrokeMap:
    """Stroke [m] at a load [kg] on a branch -> :class:`StrokeTarget`, for a wire of
    ``params`` whose stroke is counted from ``start_length`` x_0 [m]."""

    def __init__(self, params, start_length_m):
        self.params = params
        self.start_length = float(start_length_m)
        self._branches = BranchCache(params)
        terms = params.terms
        self._thermal = terms.alpha_P != 0.0 or terms.alpha_MF != 0.0
        self._last = (None, None, None, None)   # (stroke, load, direction, target)
        self._ends_of, self._ends = None, None  # a branch's constants, its ends' T [degC]

    def target(self, stroke, load, direction=HEATING):
        """The :class:`StrokeTarget` of ``stroke`` [m] under ``load`` [kg] on the major branch
        of ``direction`` (+1 heating, -1 cooling). No argument checks: the loop's hot path."""
        last_stroke, last_load, last_direction, last = self._last
        if stroke == last_stroke and load == last_load and direction == last_direction:
            return last
        target = self._solve(stroke, self._branches.get(load, direction))
        self._last = (stroke, load, direction, target)
        return target

    def _fraction_at(self, temperature, length, constants):
        """(xi_MF, clamped): the fraction [1] whose length at ``temperature`` is ``length``."""
        params, total = self.params, constants.M
        hot = branch_length(temperature, total, 0.0, constants.xi_F_min, constants, params)
        cold = branch_length(temperature, 0.0, 0.5 * total, constants.xi_F_min + 0.5 * total,
                             constants, params)
        xi_mf = total * (length - hot) / (cold - hot)
        delta = params.saturation_margin * total
        if not xi_mf >= delta:   # also NaN
            return delta, True
        if not xi_mf <= total - delta:
            return total - delta, True
        return xi_mf, False

    def _solve(self, stroke, constants):
        params, total = self.params, constants.M
        length = self.start_length - stroke
        margin = params.saturation_margin
        delta = margin * total

        def branch_temperature(xi_mf):   # the major branch's inverse: closed form or Newton
            return temperature_of_fractions(xi_mf, total - xi_mf, constants, margin)[0]

        if not self._thermal:   # x does not depend on T: one affine solve
            xi_mf, clamped = self._fraction_at(constants.centre, length, constants)
            temperature = branch_temperature(xi_mf)
        else:   # F(T) = T'(T) - T, T' = the inverse at xi_MF(T): a root between the two ends
            if constants is not self._ends_of:   # the ends' temperatures, once per branch
                self._ends_of = constants
                self._ends = (branch_temperature(total - delta), branch_temperature(delta))
            low, high = self._ends
            temperature, before, residual_before = min(max(constants.centre, low), high), None, 0.0
            for _ in range(ROOT_CAP):
                xi_mf, clamped = self._fraction_at(temperature, length, constants)
                proposal = branch_temperature(xi_mf)
                residual = proposal - temperature
                if abs(residual) <= ROOT_TOLERANCE_K or high - low <= ROOT_TOLERANCE_K:
                    break
                if residual > 0.0:
                    low = temperature
                else:
                    high = temperature
                if before is None or residual == residual_before:   # the fixed-point step
                    step = proposal
                else:   # the secant through the last two residuals
                    step = temperature - residual * (temperature - before) / (
                        residual - residual_before)
                before, residual_before = temperature, residual
                # a step that would leave the bracket halves it instead
                temperature = step if low < step < high else 0.5 * (low + high)
            temperature = proposal
        xi_p, xi_m, xi_f = total - xi_mf, 0.5 * xi_mf, constants.xi_F_min + 0.5 * xi_mf
        reached = self.start_length - branch_length(temperature, xi_p, xi_m, xi_f, constants,
                                                    params)
        return StrokeTarget(resistance_of((xi_p, xi_m, xi_f), params),
                            stroke if not clamped else reached, temperature, clamped)


class StrokeReference:
    """R_ref(t) [ohm] of a stroke reference: ``signal`` (a ReferenceSignal of quantity
    "stroke", in mm) mapped at the load ``load`` (LoadProfile) gives at t, on the branch of
    the signal's trend (:meth:`~.signals.ReferenceSignal.trend`). A pure function of t, so
    every master and FMU that samples it at t gets the same R_ref."""

    quantity = "stroke"

    def __init__(self, signal, load, stroke_map):
        self.signal = signal
        self.load = load
        self.map = stroke_map
        self.kind, self.settings = signal.kind, signal.settings

    def as_table(self):
        """The scenario file's ``[reference]`` table (the stroke signal's, in mm)."""
        return self.signal.as_table()

    def bounds(self):
        """(lowest, highest) R_ref [ohm] the map gives: the stroke's ends at every load, on
        both branches (R_ref falls as the stroke grows)."""
        low, high = self.signal.bounds()
        values = [self.map.target(1e-3 * stroke, load, direction).R_ref
                  for stroke in (low, high) for load in self.load.values for direction in (1, -1)]
        return min(values), max(values)

    def resistance_table(self, step_s, steps):
        """R_ref at t_k = k ``step_s`` [s], k = 0 ... ``steps``, as a ``[reference]`` table in
        ohm: what a signals source without a stroke map (the FMUs') is given. A table gives
        its knots exactly at those times, so it samples the same R_ref as this map; knots
        inside a run of equal values are left out (a held stroke and load: a few knots)."""
        return step_table(step_s, [self.value(k * step_s) for k in range(steps + 1)])

    def stroke(self, t):
        """The stroke reference [m] at ``t`` [s]."""
        return 1e-3 * self.signal.value(t)

    def strokes(self, times):
        """:meth:`stroke` [m] at each of ``times`` [s], as a list (a run's rows: see
        :meth:`~.signals.ReferenceSignal.values`)."""
        return [1e-3 * value for value in self.signal.values(times)]

    def target(self, t):
        """The :class:`StrokeTarget` at ``t`` [s]."""
        return self.map.target(1e-3 * self.signal.value(t), self.load.value(t),
                               self.signal.trend(t))

    def value(self, t):
        """R_ref [ohm] at ``t`` [s]."""
        return self.target(t).R_ref
