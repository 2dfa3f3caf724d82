"""Scenarios by name: the shipped ones, the paper's set, and names or paths resolved to files."""
from pathlib import Path

from sma_fmu.console.suggest import did_you_mean
from sma_fmu.cosim.scenario.settings import CONTROLLERS, ScenarioError
from sma_fmu.files.package_data import shipped_file, shipped_files

__all__ = ["PAPER_SET", "scenario_names", "resolve_scenarios"]

PAPER_SET = tuple(f"{profile}-{controller}" for profile in ("load-step", "heavy")
                  for controller in CONTROLLERS)


def scenario_names():
    """Names (file stems) of the scenarios shipped with the package, sorted."""
    return [name[:-len(".toml")] for name in shipped_files("scenarios", ".toml")]


def resolve_scenarios(items, everything=False):
    """Scenario files for names, paths, ``"paper"`` (the paper's set) or ``everything``.

    An item that names an existing file is that file, whatever its name; otherwise it must
    be the name of a shipped scenario.
    """
    names = list(scenario_names()) if everything else []
    for item in items:
        names.extend(PAPER_SET if item == "paper" else [item])
    if not names:
        raise ScenarioError("no scenario given; name one, or use 'paper' or --all")
    paths = []
    for name in names:
        candidate = Path(name)
        if candidate.is_file():
            paths.append(candidate)
        elif candidate.exists():
            raise ScenarioError(f"{candidate}: is not a file (a scenario is a .toml file)")
        elif name in scenario_names():
            paths.append(shipped_file("scenarios", f"{name}.toml"))
        else:
            shipped = scenario_names()
            hint = did_you_mean(name, shipped + ["paper"])
            raise ScenarioError(f"unknown scenario {name!r}: no such file, and no shipped "
                                f"scenario has that name{'; ' + hint if hint else ''} "
                                f"(sma-fmu examples lists the {len(shipped)} shipped scenarios; "
                                f"'paper' names the paper's {len(PAPER_SET)})")
    return list(dict.fromkeys(paths))
