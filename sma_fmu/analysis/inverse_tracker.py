"""An achievable benchmark in any hysteresis mode: the plant's own one-step inverse.

A controller that knows the plant's whole state (temperature, direction, reversal memory)
can choose the power that puts R_(k+1) on R_ref(t_(k+1)) exactly, whenever the thermal
step allows it: the temperature comes from inverting the branch the plant will follow
(:func:`~sma_fmu.runtime.sensing.temperature_on_stack`: the present branch, or a new minor
branch from the present state after a reversal; the major branch in mode "switch"), and
the power from the thermal step, clamped into [0, P_max].

It is greedy: in mode "switch", where a small rise of R needs the far cooling branch,
it does poorly (the dynamic program of :mod:`.switch_dp` is the benchmark there), and in
either mode it cannot prepare for the reference's lower turn, after which passive cooling
is too slow (:mod:`.preview_search` can).

Optionally it prefers passive cooling: P = 0 whenever R after a passive step lies within
``tolerance`` [ohm] of the target. In mode "continuous" this turns the power into a
sawtooth at the step rate (hundreds of temperature reversals per second). The minor loops
of spec section 6 have return-point memory (:mod:`sma_fmu.runtime.minor_loops`): each small
loop closes where it began, so the sawtooth gains little, 12-20 % below the plain inverse
on the paper's reference (before that memory it ratcheted xi_MF down and tracked to a few
hundredths of an ohm, a property of the old model, not of a real wire).
"""
import numpy as np

from sma_fmu.runtime.constant_load import BranchCache
from sma_fmu.runtime.constants import COOLING, HEATING
from sma_fmu.runtime.minor_loops import push_reversal
from sma_fmu.runtime.sensing import mixed_fractions_of_resistance, temperature_on_stack

from .power_limit import PowerLimit

__all__ = ["OneStepInverse", "track"]


class OneStepInverse:
    """Perfect-knowledge one-step inverse of a runtime :class:`PlantStepper`.

    ``problem`` a :class:`~.tracking_problem.TrackingProblem`; ``power_cap`` P_max [W] or a
    :class:`~.power_limit.PowerLimit` (None: no upper limit; a current or voltage limit is
    taken at the plant's R at each step's start).
    """

    def __init__(self, problem, power_cap=None):
        self.problem = problem
        self.plant = problem.plant()
        self.limit = PowerLimit.of(power_cap)
        self._branches = BranchCache(problem.params)

    def _temperature_towards(self, reference, load, direction):
        """T [degC] on the branch the plant follows in ``direction`` that gives ``reference``."""
        plant, params = self.plant, self.problem.params
        points = []
        if plant.mode == "continuous":
            points = list(plant.reversals)
            if direction != plant.direction:
                push_reversal(points, plant.temperature, plant.xi_MF, params.memory_depth)
        constants = self._branches.get(load, direction)
        xi_mf, xi_p = mixed_fractions_of_resistance(reference, constants, params)
        return temperature_on_stack(xi_mf, xi_p, constants, direction, points,
                                    params.saturation_margin)[0].temperature

    def power_for(self, reference, load):
        """Power [W] in [0, P_max] for the next step (``load`` [kg] held) towards ``reference`` [ohm]."""
        now = self.plant.temperature
        heating = self._temperature_towards(reference, load, HEATING)
        if heating > now:
            aim = heating
        else:
            cooling = self._temperature_towards(reference, load, COOLING)
            aim = cooling if cooling < now else now
        limit = self.limit
        cap = float(limit.at(self.plant.outputs.R)) if limit.by_resistance else limit.cap
        return min(cap, max(0.0, self.problem.power_to(now, aim)))

    def passive_resistance(self, load):
        """R [ohm] after a step at 0 W with ``load`` [kg] held; the plant is left unchanged."""
        saved = self.plant.state()
        resistance = self.plant.step(0.0, load, self.problem.step_s).R
        self.plant.restore(saved)
        return resistance


def track(problem, tolerance=0.0, power_cap=None):
    """Run the one-step inverse over the problem; returns (powers [W], R_k [ohm]).

    ``tolerance`` [ohm]: P = 0 where a passive step lands within it of R_ref(t_(k+1)).
    The powers replayed through a fresh plant (:meth:`TrackingProblem.replay`) give R_k again.
    """
    inverse = OneStepInverse(problem, power_cap)
    powers = np.empty(problem.steps)
    resistances = np.empty(problem.steps + 1)
    resistances[0] = inverse.plant.outputs.R
    for k in range(problem.steps):
        load, target = float(problem.step_loads[k]), float(problem.references[k + 1])
        if tolerance > 0.0 and abs(inverse.passive_resistance(load) - target) <= tolerance:
            powers[k] = 0.0
        else:
            powers[k] = inverse.power_for(target, load)
        resistances[k + 1] = inverse.plant.step(float(powers[k]), load, problem.step_s).R
    return powers, resistances
