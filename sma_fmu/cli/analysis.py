"""Analysis command: bound, the best tracking any controller can reach on a scenario."""
from pathlib import Path

from .arguments import positive_number

__all__ = ["register"]


def _bound(args):
    from sma_fmu.analysis.bound_report import bound_markdown, bound_scenarios
    from sma_fmu.cosim.scenario import resolve_scenarios
    paths = resolve_scenarios(args.scenarios, everything=args.all)
    rows = bound_scenarios(paths, args.out, args.power_cap)
    print(bound_markdown(rows))
    print(f"written: {args.out}/bound.json, bound.md")
    return 0


def register(commands):
    """Add ``bound`` to the ``commands`` subparsers."""
    bound = commands.add_parser(
        "bound", help="lower bound and achievable benchmark of the tracking RMSE, beside each "
                      "scenario's controller")
    bound.add_argument("scenarios", nargs="*", metavar="SCENARIO",
                       help="a .toml file, the name of a shipped scenario, or 'paper'")
    bound.add_argument("--all", action="store_true", help="every shipped scenario")
    bound.add_argument("--power-cap", type=positive_number, metavar="W",
                       help="largest power the driver can give [W] (default: unlimited)")
    bound.add_argument("--out", type=Path, default=Path("results") / "bound", metavar="DIR",
                       help="output folder")
    bound.set_defaults(handler=_bound)
