"""The FMUs, one folder each, and their registry (:data:`REGISTRY`: one line per FMU).

A folder ``<Model>/`` holds all that is one FMU's own, as the Reference-FMUs keep one folder
per model:

- ``fmu.toml``, its declaration (:mod:`.declaration`): its pythonfmu slave's file name, its
  component in the closed loop, whether it has events of its own (FMI 3.0), the stimuli of
  its default experiment (the reference result's inputs) and, if it has them, the shipped
  scenario whose signals are its defaults;
- its pythonfmu slave script (the Python family: a thin adapter over ``sma_fmu.runtime``,
  shipped in the FMU; the package never imports it);
- ``<Model>.c``, the C family's adapter over the C runtime;
- ``page.html``, what its ``documentation/index.html`` tells a user about the model.

Every build (pythonfmu, the C family in FMI 2.0 and 3.0, the prebuilt binaries, the
documentation, the reference results) reads :func:`declarations`, no list of its own: a new
FMU is its folder and its line here.
"""
from functools import cache

from sma_fmu.console.suggest import did_you_mean
from sma_fmu.fmi.models.declaration import Declaration, read_declaration

__all__ = ["REGISTRY", "Declaration", "declarations", "declaration"]

REGISTRY = (
    "SmaActuator",          # the plant: the SMA wire
    "SmaFeedforward",       # the compensator: the inverse of the wire model
    "SmaPiController",      # the loop's PI block
    "SmaPwmDriver",         # the PWM wire driver
    "SmaScenarioSignals",   # a scenario's set-point and load signals
)


@cache
def declarations():
    """The :class:`Declaration` of every FMU of :data:`REGISTRY`, in its order (a tuple)."""
    return tuple(read_declaration(name) for name in REGISTRY)


def declaration(name):
    """The :class:`Declaration` of the FMU ``name``; ValueError for one not registered."""
    for declared in declarations():
        if declared.name == name:
            return declared
    hint = did_you_mean(name, REGISTRY)
    raise ValueError(f"unknown FMU {name!r}{f' ({hint})' if hint else ''}; expected one of "
                     f"{', '.join(REGISTRY)}")
