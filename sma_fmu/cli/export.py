"""Export commands: the closed loop for system-level tools (SSP package, container FMU), and
the FMI Cross-Check tree of the built FMUs."""
from pathlib import Path

from .arguments import add_fmus_argument, add_scenario_arguments, scenario_paths

__all__ = ["Fmi3ExportError", "register"]

# Why no export takes FMI 3.0 FMUs: its hosts do not run them (docs/fmus.md, FMI versions).
_NO_FMI3 = {
    "ssp": "the SSP hosts it is for do not run FMI 3.0 co-simulation (libcosimpy 0.0.6 and "
           "OMSimulator v3.0.0 crash on it)",
    "container": "the container (fmu-manipulation-toolbox) is an FMI 2.0 FMU that holds FMI "
                 "2.0 FMUs",
    "cross-check": "the tree it writes is the FMI 2.0 one (fmus/2.0/cs/...)",
}


class Fmi3ExportError(ValueError):
    """An export was asked of FMI 3.0 FMUs, which its hosts would crash on."""


def _refuse_fmi3(folder, kind):
    """Raise :class:`Fmi3ExportError` if ``folder`` holds an FMI 3.0 FMU."""
    import re
    import zipfile

    for path in sorted(Path(folder).glob("*.fmu")):
        try:
            with zipfile.ZipFile(path) as archive:
                head = archive.read("modelDescription.xml")[:4000].decode("utf-8", "replace")
        except (OSError, KeyError, zipfile.BadZipFile):
            continue  # not an FMU: the export itself names the problem
        if re.search(r'fmiVersion\s*=\s*"3', head):
            raise Fmi3ExportError(
                f"export {kind}: {path} is an FMI 3.0 FMU, and {_NO_FMI3[kind]}; export the "
                f"FMI 2.0 FMUs instead (sma-fmu build [--native])")


def _ssp(args):
    paths = scenario_paths(args)
    from sma_fmu.systems.ssp import export_ssp

    _refuse_fmi3(args.fmus, "ssp")
    for path in export_ssp(paths, args.out, args.fmus):
        print(path)
    return 0


def _container(args):
    from sma_fmu.console.extras import require
    from sma_fmu.cosim.scenario import resolve_scenarios
    from sma_fmu.systems.container import export_container

    _refuse_fmi3(args.fmus, "container")
    paths = resolve_scenarios([args.scenario])
    if len(paths) != 1:
        raise ValueError(f"SCENARIO {args.scenario!r}: names {len(paths)} scenarios; a container "
                         "holds one (export each into its own file)")
    require("systems", "export container")
    print(export_container(paths[0], args.out, args.fmus))
    return 0


def _cross_check(args):
    from sma_fmu.fmi.packaging.cross_check import export_cross_check

    _refuse_fmi3(args.fmus, "cross-check")
    for folder in export_cross_check(args.fmus, args.out):  # prints the FMUs it leaves out
        print(folder)
    return 0


def register(commands):
    """Add ``export ssp``, ``export container`` and ``export cross-check`` to ``commands``."""
    export = commands.add_parser("export", help="the closed loop for system tools: SSP, container FMU")
    kinds = export.add_subparsers(dest="kind", required=True, metavar="KIND")

    ssp = kinds.add_parser(
        "ssp", help="SSP 1.0 package(s): signals -> compensator -> PI -> plant, with the "
                    "scenario's parameters",
        description="One .ssp per scenario: --out FILE.ssp for one scenario, else --out is a "
                    "folder that gets NAME.ssp for each.")
    add_scenario_arguments(ssp)
    ssp.add_argument("--out", type=Path, required=True, metavar="FILE.ssp|DIR",
                     help="the .ssp file (one scenario) or a folder")
    add_fmus_argument(ssp, "folder of the built FMUs (sma-fmu build)")
    ssp.set_defaults(handler=_ssp)

    container = kinds.add_parser(
        "container", help="the whole closed loop of one scenario as one FMI 2.0 FMU")
    container.add_argument("scenario", metavar="SCENARIO",
                           help="a .toml file or the name of a shipped scenario")
    container.add_argument("--out", type=Path, required=True, metavar="FILE.fmu",
                           help="the container FMU to write")
    add_fmus_argument(container, "folder of the built FMUs (sma-fmu build)")
    container.set_defaults(handler=_container)

    cross = kinds.add_parser(
        "cross-check", help="the FMI Cross-Check tree of the built FMUs (fmus/2.0/cs/<platform>/"
                            "sma-fmu/<version>/<Model>/)",
        description="Per FMU with a reference result: the FMU, <Model>_ref.csv, <Model>_in.csv, "
                    "<Model>_ref.opt, ReadMe.md and LICENSE.txt; each reference is checked first.")
    add_fmus_argument(cross, "folder of the built FMUs (sma-fmu build)")
    cross.add_argument("--out", type=Path, required=True, metavar="DIR",
                       help="the folder that gets the fmus/ tree")
    cross.set_defaults(handler=_cross_check)
