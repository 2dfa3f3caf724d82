"""One scenario's closed loop as a system of FMUs: components, parameter values, connections.

The SSP package (:mod:`.ssp`) and the container FMU (:mod:`.container`) are both written
from this one description, so they wire and parameterise the loop alike. The wiring
(connections, Gauss-Seidel :data:`STEP_ORDER`) is :mod:`sma_fmu.fmi.packaging.loop_wiring`'s,
which the FMUs' documentation shows too. The "pi" controller has no compensator (the PI's
P_ff input then keeps its start, 0 W); a scenario with ``[drive] kind = "pwm"`` has a PWM
driver between the PI and the plant.

Each component's parameter values are the scenario's: every wire parameter its FMU
exposes (from the scenario's parameter file), the controller's gains and filter, the
driver's frequency and peak power, the plant's start temperature and hysteresis mode, and
the signals as JSON tables. Choices (the hysteresis mode, the inverse) are the Integer
codes of :mod:`sma_fmu.fmi.python_family.slave_support.choices`.
"""
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from sma_fmu.cosim.master import MissingFmuError, model_parameter_values, needed_fmus
from sma_fmu.files.archives import require_safe_archive
from sma_fmu.fmi.packaging.fmu_names import default_fmu_paths
from sma_fmu.fmi.packaging.loop_wiring import STEP_ORDER, Connection, loop_connections
from sma_fmu.fmi.driving.description import read_description
from sma_fmu.fmi.python_family.slave_support.choices import choice_code
from sma_fmu.runtime.scenario_signals import table_text

__all__ = ["Component", "Connection", "LoopSystem", "closed_loop", "identifier", "STEP_ORDER"]



def identifier(name):
    """``name`` as an identifier (letters, digits, underscores; a letter first), as hosts
    need for system and model names: every other character becomes "_", and a name that
    does not start with a letter gets the prefix "sma_"."""
    text = "".join(character if character.isascii() and character.isalnum() else "_"
                   for character in name)
    return text if text[:1].isalpha() else f"sma_{text}"


@dataclass(frozen=True)
class Component:
    """One FMU instance: ``name`` in the system, FMU ``model`` name, its ``fmu`` file,
    ``parameters`` (name -> float, int, bool or str) and the FMU's model ``variables`` (name ->
    fmpy's ScalarVariable, read once here for everything written from the system)."""

    name: str
    model: str
    fmu: object
    parameters: dict
    variables: dict


@dataclass(frozen=True)
class LoopSystem:
    """The closed loop of ``scenario``: components in data-flow order and their connections."""

    scenario: object
    components: tuple
    connections: tuple

    def component(self, name):
        """The component called ``name``."""
        for component in self.components:
            if component.name == name:
                return component
        raise KeyError(name)

    def in_step_order(self):
        """The components in the Gauss-Seidel order :data:`STEP_ORDER`."""
        return sorted(self.components, key=lambda component: STEP_ORDER.index(component.name))


def _version(path):
    """(path, size, modification time [ns]): a key that changes when the file does."""
    stat = Path(path).stat()
    return str(Path(path).resolve()), stat.st_size, stat.st_mtime_ns


@lru_cache(maxsize=64)
def _checked_variables(version):
    """{name: ScalarVariable} of the FMU file ``version`` (:func:`_version`), its archive
    checked as safe first; once per file version (a sweep or a bench builds many systems)."""
    require_safe_archive(version[0])  # an export packs it for hosts that unpack it
    return {v.name: v for v in read_description(version[0]).modelVariables}


def _fmu_files(scenario, fmu_dir):
    paths = default_fmu_paths(fmu_dir)
    needed = ["SmaScenarioSignals", "SmaPiController", *needed_fmus(scenario)]
    for name in needed:
        if not paths[name].is_file():
            raise MissingFmuError(f"{paths[name]} not found; build the FMUs first: "
                                  f"sma-fmu build --out {fmu_dir}")
    return paths


def _component(name, model, paths, parameters=None, params=None):
    """The :class:`Component` ``name`` of FMU ``model``; its model description is read once.

    ``params``: the wire parameters whose values the FMU exposes as parameters (then
    updated with ``parameters``).
    """
    variables = dict(_checked_variables(_version(paths[model])))
    values = {} if params is None else model_parameter_values(paths[model], params,
                                                              variables.values())
    values.update(parameters or {})
    return Component(name, model, paths[model], values, variables)


def closed_loop(scenario, fmu_dir):
    """The :class:`LoopSystem` of ``scenario`` with the FMUs built in ``fmu_dir``."""
    paths = _fmu_files(scenario, fmu_dir)
    c = scenario.controller
    components = [_component("signals", "SmaScenarioSignals", paths, {
        "reference": table_text(scenario.reference.as_table()),
        "load_profile": table_text(scenario.load.as_table())})]
    drive = scenario.drive
    connections = loop_connections(c.feedforward, drive.pwm)
    if c.feedforward:
        components.append(_component("compensator", "SmaFeedforward", paths, {
            "alpha": c.alpha, "beta": c.beta, "model_load": c.model_load,
            "adapt_to_load": c.adapt_to_load, "inverse": choice_code("inverse", c.inverse)},
            scenario.compensator_params))
    components.append(_component("pi", "SmaPiController", paths, {"Kp": c.Kp, "Ki": c.Ki}))
    if drive.pwm:
        components.append(_component("driver", "SmaPwmDriver", paths, {
            "frequency_Hz": drive.frequency_Hz, "peak_W": drive.peak_W}))
    components.append(_component("plant", "SmaActuator", paths, {
        "T_start": scenario.T_start,
        "hysteresis_mode": choice_code("hysteresis_mode", scenario.hysteresis_mode)}, scenario.params))
    return LoopSystem(scenario, tuple(components), tuple(connections))
