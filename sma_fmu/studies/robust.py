"""A tuning criterion a bench would accept: the RMSE over Monte Carlo draws of noise and wire.

``sma-fmu tune --robust`` scores a set of gains not on the scenario as it is, but on
:attr:`RobustCriterion.draws` copies of it, each with

- its own **noise stream**: the scenario's sensor seed + d (d = 0, 1, ...), where the
  scenario has a noisy ``[sensor]``;
- its own **wire**: each of :attr:`RobustCriterion.parameters` of the plant's parameter file
  times an independent factor uniform in [1 - spread, 1 + spread] (numpy's
  ``default_rng(seed)``; **choice**: spread 0.1, the issue's +-10 %). The compensator keeps the
  nominal model: a real wire differs from the model its controller was designed with.

and the score is a quantile of the draws' RMSEs (**choice**: the median by default; 0.8 or
0.9 for a cautious bench). The draws are the same for every candidate, so the optimiser
compares gains on equal terms (common random numbers).

**choice** (:data:`SPREAD_PARAMETERS`): the convection coefficient and the specific heat
(the thermal time constant and gain: drafts, mounting, the wire's batch), and the
transformation temperatures and their load slopes (the alloy's batch and training). The
resistances R_P, R_M, R_F are left out: a bench measures them, and +-10 % of them would move
the reference out of the band the wire can reach (an error no gain can change).
"""
import dataclasses
from dataclasses import dataclass

import numpy as np

from sma_fmu.cosim.noise_seeds import with_seed

__all__ = ["SPREAD_PARAMETERS", "RobustCriterion", "draw_scenarios", "robust_value"]

SPREAD_PARAMETERS = ("h_c", "c_p", "a_h", "a_c", "b_h", "b_c")


@dataclass(frozen=True)
class RobustCriterion:
    """``draws`` Monte Carlo copies, factors in [1 - ``spread``, 1 + ``spread``] on
    ``parameters``, drawn from ``seed``; the score is the ``quantile`` of their RMSEs."""

    draws: int = 5
    spread: float = 0.1
    quantile: float = 0.5
    seed: int = 1
    parameters: tuple = SPREAD_PARAMETERS

    def __post_init__(self):
        if isinstance(self.draws, bool) or not isinstance(self.draws, int) or self.draws < 1:
            raise ValueError(f"draws must be a whole number >= 1, got {self.draws!r}")
        if not 0.0 <= self.spread < 1.0:
            raise ValueError(f"spread must be in [0, 1), got {self.spread!r}")
        if not 0.0 <= self.quantile <= 1.0:
            raise ValueError(f"quantile must be in [0, 1], got {self.quantile!r}")

    def factors(self):
        """(draws, parameters) array of the factors [1] on the wire's parameters."""
        rng = np.random.default_rng(self.seed)
        return rng.uniform(1.0 - self.spread, 1.0 + self.spread,
                           size=(self.draws, len(self.parameters)))

    def as_dict(self):
        """JSON-ready settings, with the factors of each draw."""
        return {"draws": self.draws, "spread": self.spread, "quantile": self.quantile,
                "seed": self.seed, "parameters": list(self.parameters),
                "factors": self.factors().tolist()}


def draw_scenarios(scenario, criterion):
    """The :attr:`~RobustCriterion.draws` copies of ``scenario`` (see the module docstring)."""
    nominal = scenario.parameter_set
    params = nominal.params
    copies = []
    for draw, factors in enumerate(criterion.factors()):
        changed = {name: getattr(params, name) * float(factor)
                   for name, factor in zip(criterion.parameters, factors)}
        wire = dataclasses.replace(nominal, params=params.replace(**changed))
        copy = dataclasses.replace(scenario, parameter_set=wire,
                                   compensator_parameter_set=scenario.compensator_parameter_set
                                   or nominal)
        if scenario.sensor.noise_ohm_rms:
            copy = with_seed(copy, scenario.sensor.seed + draw)
        copies.append(copy)
    return copies


def robust_value(rmses, quantile):
    """The ``quantile`` of RMSEs [ohm] along the last axis (numpy's linear interpolation)."""
    return np.quantile(np.asarray(rmses, dtype=float), quantile, axis=-1)
