"""Co-simulation command: run scenarios and write their results."""
from pathlib import Path

from .arguments import (add_fmus_argument, add_quiet_argument, add_scenario_arguments,
                        positive_number, scenario_paths)

__all__ = ["register"]


def _run(args):
    from sma_fmu.console.extras import require
    paths = scenario_paths(args)
    if args.format == "parquet":
        require("parquet", "--format parquet")
    if args.path in ("ssp", "container"):
        require("systems", f"--path {args.path}")
    from sma_fmu.console.progress import echo
    from sma_fmu.systems.runner import timed_run
    timed_run(paths, args.out, args.path, args.fmus, progress=echo,
              output_interval_s=args.output_interval, fmt=args.format, master=args.master,
              events=args.events, timeout_s=args.timeout, figures=args.figures)
    return 0


def register(commands):
    """Add ``run`` to the ``commands`` subparsers."""
    run = commands.add_parser(
        "run", help="run scenarios (names, files, 'paper' or --all): CSV, metrics, reports; "
             "figures with --figures")
    add_scenario_arguments(run)
    run.add_argument("--out", type=Path, default=Path("results"), metavar="DIR", help="output folder")
    run.add_argument("--path", choices=("fmu", "library", "ssp", "container"), default="fmu",
                     help="fmu: the FMUs under fmpy; library: the steppers directly; ssp: the "
                          "SSP package in libcosim (Jacobi); container: the one-FMU loop in libcosim")
    add_fmus_argument(run)
    run.add_argument("--master", choices=("fmpy", "c"), default="fmpy",  # runner.FMU_MASTERS
                     help="the FMU path's master: fmpy (default; Python) or c (the C master: "
                          "the FMUs stepped in one C process, the same results to the bit)")
    run.add_argument("--events", action="store_true",
                     help="FMI 3.0 FMUs only, fmpy master: instantiate with event mode and early "
                          "return; the plant steps from edge to edge of the PWM wave, the rows "
                          "stay on the fixed step grid")
    run.add_argument("--timeout", type=positive_number, metavar="S",
                     help="with --master c: stop a run whose C master sends no rows for S "
                          "seconds (a hung FMU; default 60)")  # c_master.DEFAULT_TIMEOUT_S
    run.add_argument("--output-interval", type=positive_number, metavar="S",
                     help="record every k-th step in the time series and figures: S seconds, a "
                          "whole number of steps (default: the scenario's output_interval_s, else "
                          "every step); the metrics always use every step")
    run.add_argument("--format", choices=("csv", "parquet"), default="csv",  # recording.FORMATS
                     help="time-series file: timeseries.csv (default) or timeseries.parquet")
    figures = run.add_mutually_exclusive_group()
    figures.add_argument("--figures", action="store_true",
                         help="also draw the figures (NAME/figure.png, comparison-GROUP.png); "
                              "without it, the time series, metrics and reports only")
    figures.add_argument("--no-figures", action="store_true",
                         help="no figures (the default; kept for scripts that say so)")
    add_quiet_argument(run)
    run.set_defaults(handler=_run)
