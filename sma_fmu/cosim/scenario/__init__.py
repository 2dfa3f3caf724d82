"""Scenarios: what to simulate, with which controller, for how long (docs/scenarios.md).

- :mod:`~.settings`: what a validated scenario holds (:class:`Scenario`, its controller, drive
  and analysis settings) and :class:`ScenarioError`;
- :mod:`~.reading`: read and check a scenario file (the format is in its docstring);
  :func:`load_scenario`, :func:`scenario_from_document`;
- :mod:`~.names`: the shipped scenarios and the paper's set; names or paths resolved to files
  (:func:`resolve_scenarios`).

The reading's names are imported at first use: naming a scenario (the command line's first
check) does not wait for the file reader's imports.
"""
from sma_fmu.cosim.scenario.names import PAPER_SET, resolve_scenarios, scenario_names
from sma_fmu.cosim.scenario.settings import (CONTROLLERS, AnalysisWindow, ControllerSettings,
                                             DriveSettings, Scenario, ScenarioError,
                                             SensorSettings, default_analysis)

__all__ = ["ScenarioError", "ControllerSettings", "DriveSettings", "SensorSettings",
           "AnalysisWindow", "Scenario",
           "CONTROLLERS", "PAPER_SET", "MAX_STEPS", "load_scenario", "read_scenario_document",
           "scenario_from_document", "check_sections", "default_analysis", "scenario_names",
           "resolve_scenarios"]

_READING = ("MAX_STEPS", "check_sections", "load_scenario", "read_scenario_document",
            "scenario_from_document")


def __getattr__(name):
    if name in _READING:
        from sma_fmu.cosim.scenario import reading
        return getattr(reading, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
