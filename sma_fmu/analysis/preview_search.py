"""An achievable benchmark with preview: a receding-horizon search over the runtime plant.

The one-step inverse (:mod:`.inverse_tracker`) is greedy: it never gives up a little error
now for less later, so it cannot see the reference's lower turn coming, after which passive
cooling is too slow. This search knows the whole future reference and loads. Every
``block`` steps it tries a few candidate power profiles on copies of the plant over the
next ``horizon`` steps and applies the first block of the best one:

- the one-step inverse all along (the base policy);
- 0 W or P_max held for 1, 2, 4 (0 W also 8) blocks, then the base policy;
- the one-step inverse aimed ``offset`` ohm above or below R_ref for 1 or 4 blocks, then
  the base policy;
- the rest of the previous block's best plan (so a plan that pays off late is kept).

A candidate's cost is its squared error over the horizon's samples in the metric window.
Every power is in [0, P_max(R_k)] (the driver's limit at the plant's R at the step's start,
as the one-step inverse takes it), and the plant is the runtime's :class:`PlantStepper`,
so the powers replayed through a fresh plant give the same R_k: the RMSE is achievable, an
upper bound on the optimum in any hysteresis mode. Cost: about (candidates x horizon / block)
plant steps and inversions per step, 1-2 min of CPU for a 30-s scenario at the defaults.

It is a heuristic, and not monotone in the horizon: the model's reversal memory makes the
run settle into one periodic regime or another, and a longer horizon can pick a worse one
(:data:`HORIZONS`). In mode "switch" its base policy chatters and it is far above the node
program's path (:mod:`.switch_dp`); it never goes below the rigorous bound there (tested).
"""
import copy
import math

import numpy as np

from .inverse_tracker import OneStepInverse
from .power_limit import PowerLimit

__all__ = ["PreviewSearch", "preview_search", "BLOCK_STEPS", "HORIZON_STEPS", "HORIZONS"]

BLOCK_STEPS = 20      # steps between two decisions (20 ms at the paper's 1-ms step)
HORIZON_STEPS = 400   # steps each candidate is rolled out over (0.4 s: a lower turn and after)
HORIZONS = (200, 300, 400)   # steps: the horizons `sma-fmu bound --preview` tries (not monotone:
                             # 300 gave 0.148 ohm on the bench load-step, 400 0.180, 800 0.421)
HOLDS = (1, 2, 4, 8)  # blocks a candidate holds 0 W
FULL = (1, 2, 4)      # blocks a candidate holds P_max
OFFSETS = (-0.5, 0.25, 0.5, 1.0, 2.0)   # ohm: aim above (cooler) or below R_ref
AIM_BLOCKS = (1, 4)   # blocks a candidate aims off R_ref


def _copy_plant(plant):
    """An independent copy of a runtime plant: its only mutable attribute is the reversal
    stack (a list of immutable points); everything else is numbers, tuples or shared caches."""
    twin = copy.copy(plant)
    twin.reversals = list(plant.reversals)
    return twin


class PreviewSearch:
    """Receding-horizon search with perfect preview over a :class:`~.tracking_problem.TrackingProblem`.

    ``power_cap`` P_max [W] or a :class:`~.power_limit.PowerLimit` (None: no upper limit);
    ``block`` and ``horizon`` in steps.
    """

    def __init__(self, problem, power_cap=None, block=BLOCK_STEPS, horizon=HORIZON_STEPS):
        self.problem = problem
        self.limit = PowerLimit.of(power_cap)
        self.block, self.horizon = block, horizon
        self._inverse = OneStepInverse(problem, self.limit)
        self._references = problem.references.tolist()
        self._loads = problem.step_loads.tolist()
        self._weights = problem.weights.tolist()

    def candidates(self):
        """{name: prefix}: a prefix lists ("power", P [W]) or ("aim", offset [ohm]) per step;
        the base policy follows it."""
        block = self.block
        found = {"one-step inverse": []}
        found.update({f"0 W for {m} blocks": [("power", 0.0)] * (m * block) for m in HOLDS})
        found.update({f"P_max for {m} blocks": [("power", math.inf)] * (m * block) for m in FULL})
        found.update({f"aim {offset:+g} ohm for {m} blocks": [("aim", offset)] * (m * block)
                      for offset in OFFSETS for m in AIM_BLOCKS})
        return found

    def _cap(self, plant):
        limit = self.limit
        return float(limit.at(plant.outputs.R)) if limit.by_resistance else limit.cap

    def rollout(self, plant, start, prefix):
        """(cost [ohm^2], powers [W]) of ``prefix`` then the base policy, from step ``start``
        over the horizon; ``plant`` (a copy) is stepped along."""
        inverse, step, h = self._inverse, plant.step, self.problem.step_s
        inverse.plant = plant
        references, loads, weights = self._references, self._loads, self._weights
        cost, powers = 0.0, []
        for index in range(start, min(start + self.horizon, self.problem.steps)):
            load, target = loads[index], references[index + 1]
            offset = 0.0
            if index - start < len(prefix):
                kind, value = prefix[index - start]
                if kind == "power":
                    power = min(value, self._cap(plant))
                    powers.append(power)
                    error = step(power, load, h).R - target
                    cost += weights[index + 1] * error * error
                    continue
                offset = value
            power = inverse.power_for(target + offset, load)
            powers.append(power)
            error = step(power, load, h).R - target
            cost += weights[index + 1] * error * error
        return cost, powers

    def run(self):
        """(powers [W], R_k [ohm], {candidate name: blocks it won}) over the whole problem."""
        problem = self.problem
        plant = problem.plant()
        candidates = self.candidates()
        powers = np.empty(problem.steps)
        resistances = np.empty(problem.steps + 1)
        resistances[0] = plant.outputs.R
        wins, kept, start = {}, [], 0
        while start < problem.steps:
            trials = dict(candidates)
            if kept:
                trials["the previous plan"] = [("power", power) for power in kept]
            best = None
            for name, prefix in trials.items():
                cost, planned = self.rollout(_copy_plant(plant), start, prefix)
                if best is None or cost < best[0]:
                    best = (cost, name, planned)
            _, name, planned = best
            wins[name] = wins.get(name, 0) + 1
            for index in range(start, min(start + self.block, problem.steps)):
                powers[index] = planned[index - start]
                resistances[index + 1] = plant.step(powers[index], self._loads[index],
                                                    problem.step_s).R
            kept = planned[self.block:]
            start += self.block
        return powers, resistances, wins


def preview_search(problem, power_cap=None, block=BLOCK_STEPS, horizon=HORIZON_STEPS):
    """(powers [W], R_k [ohm]) of :class:`PreviewSearch` over ``problem``; the powers replayed
    through a fresh plant (:meth:`TrackingProblem.replay`) give R_k again."""
    powers, resistances, _ = PreviewSearch(problem, power_cap, block, horizon).run()
    return powers, resistances
