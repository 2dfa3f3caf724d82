"""Analysis command: bound, the best tracking any controller can reach on a scenario."""
from pathlib import Path

from .arguments import add_scenario_arguments, positive_number, scenario_paths

__all__ = ["register"]


def _bound(args):
    from sma_fmu.analysis.bound_report import bound_markdown, bound_scenarios
    rows = bound_scenarios(scenario_paths(args), args.out, args.power_cap,
                           current_A=args.current_limit, voltage_V=args.voltage_limit,
                           preview=args.preview)
    print(bound_markdown(rows))
    print(f"written: {args.out}/bound.json, bound.md")
    return 0


def register(commands):
    """Add ``bound`` to the ``commands`` subparsers."""
    bound = commands.add_parser(
        "bound", help="lower bound and achievable benchmark of the tracking RMSE, beside each "
                      "scenario's controller")
    add_scenario_arguments(bound)
    bound.add_argument("--power-cap", type=positive_number, metavar="W",
                       help="largest power the driver can give [W] (default: unlimited)")
    bound.add_argument("--current-limit", type=positive_number, metavar="A",
                       help="the driver's current limit [A], P <= I^2 R at the wire's R "
                            "(default: the scenario's [drive] I_max_A, else none)")
    bound.add_argument("--voltage-limit", type=positive_number, metavar="V",
                       help="the driver's voltage limit [V], P <= V^2 / R (default: the "
                            "scenario's [drive] V_max_V, else none)")
    bound.add_argument("--preview", action="store_true",
                       help="continuous mode: add benchmarks that search with the reference's "
                            "future known (receding horizon over the plant; minutes per scenario)")
    bound.add_argument("--out", type=Path, default=Path("results") / "bound", metavar="DIR",
                       help="output folder")
    bound.set_defaults(handler=_bound)
