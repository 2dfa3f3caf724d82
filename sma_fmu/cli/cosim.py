"""Co-simulation command: run scenarios and write their results."""
from pathlib import Path

from sma_fmu.fmi.build import DEFAULT_FMU_DIR

__all__ = ["register"]


def _run(args):
    from sma_fmu.cosim.runner import timed_run
    from sma_fmu.cosim.scenario import resolve_scenarios
    paths = resolve_scenarios(args.scenarios, everything=args.all)
    timed_run(paths, args.out, args.path, args.fmus)
    return 0


def register(commands):
    """Add ``run`` to the ``commands`` subparsers."""
    run = commands.add_parser(
        "run", help="run scenarios (names, files, 'paper' or --all): CSV, metrics, figures")
    run.add_argument("scenarios", nargs="*", metavar="SCENARIO",
                     help="a .toml file, the name of a shipped scenario, or 'paper'")
    run.add_argument("--all", action="store_true", help="every shipped scenario")
    run.add_argument("--out", type=Path, default=Path("results"), metavar="DIR", help="output folder")
    run.add_argument("--path", choices=("fmu", "library", "ssp", "container"), default="fmu",
                     help="fmu: the FMUs under fmpy; library: the steppers directly; ssp: the "
                          "SSP package in libcosim (Jacobi); container: the one-FMU loop in libcosim")
    run.add_argument("--fmus", type=Path, default=DEFAULT_FMU_DIR, metavar="DIR",
                     help="folder of the built FMUs")
    run.set_defaults(handler=_run)
