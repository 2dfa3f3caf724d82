"""Study commands: sweep (a study spec on Dask) and tune (PI and compensator gains)."""
from pathlib import Path

from sma_fmu.console.extras import require

from .arguments import (add_quiet_argument, add_scenario_arguments, bounded_integer,
                        bounded_number, require_inputs, scenario_paths)

# choice: ranges wide enough for any real study, narrow enough that a typo cannot start a
# run that would never end or exhaust memory (checked before any work starts)
MAX_WORKERS = 256
MAX_GENERATIONS = 1000
MAX_POPULATION = 100
MAX_DRAWS = 100

__all__ = ["register"]


def _sweep(args):
    require_inputs((args.spec, "study spec"))
    require("studies", "sweep")
    from sma_fmu.studies.sweep import run_sweep
    out = args.out or Path("results") / f"sweep-{Path(args.spec).stem}"
    summary = run_sweep(args.spec, out, args.scheduler, args.workers, progress=not args.quiet,
                        fmu_dir=args.fmus)
    status = summary["status"]
    print(f"{summary['runs']} runs: {status['ok']} ok, {status['failed']} failed, "
          f"{status['error']} task errors")
    for name, entry in summary["scenarios"].items():
        stats = entry["rmse_ohm"]
        if stats:
            print(f"{name}: RMSE {stats['mean']:.4f} ohm mean, {stats['p05']:.4f} ... "
                  f"{stats['p95']:.4f} (5-95 %), best {entry['best']['rmse_ohm']:.4f} ohm "
                  f"(run {entry['best']['run_id']})")
    print(f"written: {out}/results.parquet, results.csv, summary.md, summary.json, figures/")
    return 0


def _tune(args):
    paths = scenario_paths(args)
    require("studies", "tune")
    from sma_fmu.console.progress import echo
    from sma_fmu.studies.robust import RobustCriterion
    from sma_fmu.studies.tuning import run_tuning
    out = args.out or Path("results") / "tune"
    robust = None
    if args.robust:
        robust = RobustCriterion(args.draws, args.spread, args.quantile, args.seed)
    run_tuning(paths, out, seed=args.seed, generations=args.generations,
               population=args.population, stop_time_s=args.stop_time, progress=echo,
               robust=robust, criterion=args.criterion, joint=args.joint)
    print(f"written: {out}/report.md, report.json, NAME/controller.toml")
    return 0


def register(commands):
    """Add ``sweep`` and ``tune`` to the ``commands`` subparsers."""
    sweep = commands.add_parser("sweep", help="run a study spec (grid, random, LHS, Monte "
                                              "Carlo) on Dask; results table, summary, figures")
    sweep.add_argument("spec", metavar="SPEC.toml", help="study spec (see docs/studies.md)")
    sweep.add_argument("--scheduler", metavar="ADDRESS",
                       help="address of a running Dask scheduler (default: a local cluster)")
    sweep.add_argument("--workers", type=bounded_integer(1, MAX_WORKERS), metavar="N",
                       help=f"worker processes of the local cluster, 1-{MAX_WORKERS} "
                            "(default: one per core)")
    sweep.add_argument("--out", type=Path, metavar="DIR",
                       help="output folder (default: results/sweep-SPEC); rerun to resume")
    add_quiet_argument(sweep)
    sweep.add_argument("--fmus", type=Path, metavar="DIR",
                       help="run every run through the C master over the FMUs in DIR (sma-fmu "
                            "build --native: FMU-path studies at C speed); default: the batch engine")
    sweep.set_defaults(handler=_sweep)

    tune = commands.add_parser("tune", help="optimise Kp, Ki (and alpha, beta with "
                                            "feedforward) for the RMSE of R, or of a stroke "
                                            "scenario's stroke; [controller] snippets")
    add_scenario_arguments(tune)
    tune.add_argument("--out", type=Path, metavar="DIR", help="output folder (default: results/tune)")
    tune.add_argument("--seed", type=bounded_integer(0, 2 ** 32 - 1), default=1,
                      help="seed of differential evolution, 0-4294967295")
    tune.add_argument("--generations", type=bounded_integer(1, MAX_GENERATIONS), default=30,
                      help=f"most generations of differential evolution, 1-{MAX_GENERATIONS}")
    tune.add_argument("--population", type=bounded_integer(1, MAX_POPULATION), default=12,
                      help=f"population size per tuned parameter (scipy's popsize), 1-{MAX_POPULATION}")
    tune.add_argument("--stop-time", type=float, metavar="S",
                      help="tune over the first S seconds, checked as a scenario's stop_time_s "
                           "(at most 4,000,000 steps) (default: the scenario's duration)")
    tune.add_argument("--criterion", choices=("stroke", "resistance"),   # criterion.CRITERIA
                      help="what is minimised: the RMSE of the stroke [um] or of R - R_ref "
                           "[ohm] (default: stroke for a stroke scenario, else resistance; "
                           "stroke on a resistance scenario is refused)")
    tune.add_argument("--joint", action="store_true",
                      help="one gain set for all the scenarios given: minimise the worst of "
                           "their scores relative to their given gains' (they must tune the "
                           "same gains)")
    tune.add_argument("--robust", action="store_true",
                      help="score gains by a quantile of the RMSE over Monte Carlo draws of "
                           "the noise stream and the wire (+- --spread on its thermal and "
                           "transformation parameters; docs/studies.md)")
    tune.add_argument("--draws", type=bounded_integer(1, MAX_DRAWS), default=5,
                      help=f"with --robust: draws per candidate, 1-{MAX_DRAWS} (default 5)")
    tune.add_argument("--spread", type=bounded_number(0.0, 0.5, closed=True), default=0.1,
                      help="with --robust: relative spread of the wire's parameters, 0-0.5 "
                           "(default 0.1: +-10 %%)")
    tune.add_argument("--quantile", type=bounded_number(0.0, 1.0, closed=True), default=0.5,
                      help="with --robust: the quantile of the draws' RMSEs minimised, 0-1 "
                           "(default 0.5: the median)")
    add_quiet_argument(tune)
    tune.set_defaults(handler=_tune)
