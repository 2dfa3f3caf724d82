"""The controller's gains: one table of their names in a scenario file, in the parameter file
and in the loop.

A gain has one name in the loop (the field of the scenario's controller settings and the
parameter of the FMU that takes it), a key in a scenario file's ``[controller]`` table (its
unit in the name), and the parameter file's entry that gives its default (``[control]``;
the phase-lag filter's alpha defaults to the wire's thermal time constant, see
:class:`~sma_fmu.runtime.parameters.WireParameters`). The scenario reader, the study
overrides, the tuner and the loop's parameter values all read :data:`GAINS`.
"""
from dataclasses import dataclass

__all__ = ["Gain", "GAINS", "GAIN_KEYS"]


@dataclass(frozen=True)
class Gain:
    """One gain: ``name`` in the loop, ``key`` in a scenario file's ``[controller]``,
    ``default`` the parameter-file attribute its default comes from, ``component`` the loop
    component whose FMU takes it as a parameter (called ``name`` there)."""

    name: str
    key: str
    default: str
    component: str


GAINS = (
    Gain("Kp", "Kp_W_per_ohm", "Kp", "pi"),                       # [W/ohm]
    Gain("Ki", "Ki_W_per_ohm_s", "Ki", "pi"),                     # [W/(ohm.s)]
    Gain("alpha", "alpha_s", "phase_lag_alpha", "compensator"),   # [s] phase-lag filter
    Gain("beta", "beta_s", "beta", "compensator"),                # [s] phase-lag filter
    Gain("model_load", "model_load_kg", "model_load", "compensator"),   # [kg] fixed inverse
)
GAIN_KEYS = {gain.name: gain.key for gain in GAINS}   # name -> scenario-file key
