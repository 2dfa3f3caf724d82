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
iterates T -> xi_MF (the affine solve at T) -> T = the major branch's inverse at xi_MF
(:func:`~.sensing.temperature_of_fractions`: closed form, or the two-stage Newton search of
:mod:`.two_stage_root`), from the branch's centre, until T moves by less than
:data:`~.two_stage_root.ROOT_TOLERANCE_K`. The root lies between the temperatures of the
branch's two ends (T' never leaves them), and each round narrows that bracket by the sign of
T' - T; a step that would leave it halves it instead, as the two-stage search does (near
saturation the fixed point alone would jump between the ends). Inside the transformation a
round shrinks the error by the ratio of the thermal slope of x to its transformation slope
(a few per cent for the Flexinol fit): 4-6 rounds; at most :data:`~.two_stage_root.ROOT_CAP`.

The branch is the major branch of ``direction`` (the sign of the stroke reference's last
change: a rising stroke heats). On a minor branch the wire holds the same (R, xi_MF) pairs;
only the thermal expansion's T differs, by less than the hysteresis width.

**Reach:** xi_MF is clamped into [delta, M - delta], delta = saturation_margin M, as the
temperature-sensing inverse clamps it: a stroke beyond what the wire gives at that load (more
than all of M transformed to P, or less than none) maps to the end's R_ref, and the target
says ``clamped`` and the stroke it does give.

**Cost per step:** the last target is kept, so a reference and load held over a step cost one
comparison; a new (stroke, load, direction) costs one affine solve without thermal expansion,
else 4-6 branch inverses (``sma-fmu bench`` measures both).
"""
from collections import namedtuple

from .constant_load import BranchCache
from .constants import HEATING
from .phases import resistance_of
from .plant import PlantStepper, branch_length
from .sensing import temperature_of_fractions
from .two_stage_root import ROOT_CAP, ROOT_TOLERANCE_K

__all__ = ["StrokeTarget", "StrokeMap", "StrokeReference", "start_length"]

StrokeTarget = namedtuple("StrokeTarget", ["R_ref", "stroke", "temperature", "clamped"])
StrokeTarget.__doc__ = """Where the wire gives a stroke on a branch at one load.

R_ref : the resistance there [ohm]; stroke : the stroke it gives [m] (the asked one unless
clamped); temperature : the branch's temperature there [degC]; clamped : the asked stroke
lay beyond the reach at that load (see the module docstring).
"""


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
        else:   # T -> xi_MF(T) -> T' has its root between the branch's two ends
            low, high = branch_temperature(total - delta), branch_temperature(delta)
            temperature = min(max(constants.centre, low), high)
            for _ in range(ROOT_CAP):
                xi_mf, clamped = self._fraction_at(temperature, length, constants)
                proposal = branch_temperature(xi_mf)
                if abs(proposal - temperature) <= ROOT_TOLERANCE_K or high - low <= ROOT_TOLERANCE_K:
                    break
                if proposal > temperature:
                    low = temperature
                else:
                    high = temperature
                # the fixed-point step where it stays inside the bracket, else its middle
                temperature = proposal if low < proposal < high else 0.5 * (low + high)
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

    def stroke(self, t):
        """The stroke reference [m] at ``t`` [s]."""
        return 1e-3 * self.signal.value(t)

    def target(self, t):
        """The :class:`StrokeTarget` at ``t`` [s]."""
        return self.map.target(1e-3 * self.signal.value(t), self.load.value(t),
                               self.signal.trend(t))

    def value(self, t):
        """R_ref [ohm] at ``t`` [s]."""
        return self.target(t).R_ref
