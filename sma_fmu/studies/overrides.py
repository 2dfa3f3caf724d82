"""Scenarios with fields overridden: the unit of every study.

An override names a field as ``"section.key"``, with the section and key of a scenario
file (units in the key names, as there), or a parameter of
:data:`~sma_fmu.runtime.parameters.PARAMETER_SPECS` (in its unit) as ``"wire.NAME"`` (the
real wire: the plant) or ``"model.NAME"`` (the compensator's inverse model). Both start
from the scenario's parameter file, so ``wire.*`` alone makes a wire that differs from the
model the compensator was designed with, as a real one does; give the same change as
``model.*`` too for a compensator identified on that very wire::

    {"controller.Kp_W_per_ohm": 0.5,       # gains, filter, model load, controller kind
     "scenario.stop_time_s": 10.0,         # duration (and step_s)
     "plant.hysteresis_mode": "continuous",
     "load.values_kg": 0.1,                # a number: that load throughout
     "reference.amplitude_ohm": 4.0,
     "sensor.seed": 3,                     # the sensor's noise stream (a [sensor] section)
     "drive.I_max_A": 0.4,                 # the driver's current limit
     "wire.a_h": 70.0}                     # degC, the plant's wire only

The changed document goes through the scenario loader, so every value is checked as in a
file and a bad one raises :class:`StudyError` naming the override and the value. A
number for ``load.values_kg`` means a constant load (``times_s`` becomes [0]);
overriding ``reference.kind`` replaces the whole ``[reference]`` table by the overrides.
"""
import copy
from dataclasses import dataclass, replace
from pathlib import Path

from sma_fmu.cosim.scenario import (Scenario, ScenarioError, read_scenario_document,
                                    resolve_scenarios, scenario_from_document)
from sma_fmu.fmi.loop.gains import GAIN_KEYS
from sma_fmu.wire.parameter_file import load_parameter_set
from sma_fmu.runtime.parameters import PARAMETER_SPECS, ParameterError

__all__ = ["StudyError", "SECTIONS", "ScenarioTemplate", "template", "with_overrides"]

SECTIONS = ("scenario", "reference", "load", "controller", "plant", "drive", "sensor", "wire",
            "model")
_WIRE = {spec.name for spec in PARAMETER_SPECS} - set(GAIN_KEYS)   # the gains are the controller's


class StudyError(ValueError):
    """A study input is wrong; the message names the file or override and the value."""


@dataclass(frozen=True)
class ScenarioTemplate:
    """A scenario file read once: its document and parameter set, ready for overrides.

    Plain data (it pickles), so it travels to Dask workers without the files.
    """

    name: str
    path: Path
    document: dict
    parameter_set: object

    def scenario(self, overrides=None):
        """The :class:`Scenario` with ``overrides`` (a mapping, see the module docstring)."""
        return with_overrides(self, overrides or {})


def template(scenario):
    """A :class:`ScenarioTemplate` of a scenario file, a shipped scenario's name, or a template."""
    if isinstance(scenario, ScenarioTemplate):
        return scenario
    if isinstance(scenario, Scenario):
        scenario = scenario.path
    path = resolve_scenarios([str(scenario)])[0]
    document = read_scenario_document(path)
    base = scenario_from_document(document, path)    # checks the file and reads its model
    return ScenarioTemplate(path.stem, Path(path), document, base.parameter_set)


def _describe(overrides):
    return ", ".join(f"{key} = {value!r}" for key, value in overrides.items())


def _split(overrides):
    """({section: {key: value}} of scenario-file fields, {name: value} of the wire, of the model)."""
    tables, wire, model = {}, {}, {}
    for name, value in overrides.items():
        section, _, key = str(name).partition(".")
        if section not in SECTIONS or not key:
            raise StudyError(f"override {name!r}: expected SECTION.KEY with SECTION one of "
                             f"{', '.join(SECTIONS)} (e.g. controller.Kp_W_per_ohm)")
        if section in ("wire", "model"):
            if key in GAIN_KEYS:
                raise StudyError(f"override {name!r}: a controller setting; use "
                                 f"controller.{GAIN_KEYS[key]}")
            if key not in _WIRE:
                raise StudyError(f"override {name!r}: unknown wire parameter {key!r}; expected "
                                 f"one of {', '.join(sorted(_WIRE))}")
            (wire if section == "wire" else model)[key] = value
        else:
            tables.setdefault(section, {})[key] = value
    return tables, wire, model


def _parameter_set(base, model):
    """The scenario's parameter set: the template's, or the file an override of
    ``scenario.model`` names (relative to the scenario file, like the key in a file)."""
    if model is None:
        return base.parameter_set
    if not isinstance(model, (str, Path)):
        raise ScenarioError(f"{base.path}: [scenario] model must be a path, got {model!r}")
    return load_parameter_set(base.path.parent / model)


def with_overrides(base, overrides):
    """The :class:`Scenario` of ``base`` (a :class:`ScenarioTemplate`) with ``overrides``."""
    tables, wire, model = _split(overrides)
    document = copy.deepcopy(base.document)
    load = tables.get("load", {})
    if isinstance(load.get("values_kg"), (int, float)) and not isinstance(load["values_kg"], bool):
        load["values_kg"] = [load["values_kg"]]
        load.setdefault("times_s", [0.0])
    if "kind" in tables.get("reference", {}):
        document["reference"] = {}
    for section, values in tables.items():
        document.setdefault(section, {}).update(values)
    try:
        nominal = _parameter_set(base, tables.get("scenario", {}).get("model"))
        plant = replace(nominal, params=nominal.params.replace(**wire)) if wire else nominal
        scenario = scenario_from_document(document, base.path, plant)
        if wire or model:
            compensator = replace(nominal, params=nominal.params.replace(**model)) if model \
                else nominal
            scenario = replace(scenario, compensator_parameter_set=compensator)
    except (ScenarioError, ParameterError, TypeError) as error:
        raise StudyError(f"{error} (with overrides {_describe(overrides)})") from None
    return scenario
