"""Identification commands: fit (parameters from measurements), synth (synthetic measurements)."""
from pathlib import Path

from .arguments import finite_number, nonnegative_number, number_list, positive_number

__all__ = ["register"]

EXPERIMENTS = ("constant-load", "constant-temperature")


def _fit(args):
    from sma_fmu.identification.runner import format_report, run_fit
    out = args.out or Path("results") / f"fit-{args.experiment}"
    report = run_fit(args.experiment, args.files, out, args.model,
                     progress=lambda text: print(text, flush=True))
    print(format_report(report))
    print(f"written: {out}/identified.toml, report.json, figures")
    return 0


def _synth(args):
    from sma_fmu.identification.synthetic import (constant_load_rows, constant_temperature_rows,
                                                  write_rows)
    from sma_fmu.parameter_file import load_parameter_set
    params = load_parameter_set(args.model).params
    if args.experiment == "constant-load":
        rows = constant_load_rows(params, args.loads or [0.0032, 0.05, 0.15, 0.25], args.t_min,
                                  args.t_max, args.t_step, args.noise_ohm, args.noise_K, args.seed,
                                  not args.no_direction)
    else:
        rows = constant_temperature_rows(params, args.temperature,
                                         args.loads or [0.0, 0.1, 0.03, 0.2, 0.03, 0.3],
                                         args.load_step, args.noise_ohm, args.noise_K, args.seed)
    write_rows(args.out, rows)
    print(f"{args.out}: {len(rows)} rows ({args.experiment}, seed {args.seed})")
    return 0


def register(commands):
    """Add ``fit`` and ``synth`` to the ``commands`` subparsers."""
    fit = commands.add_parser("fit", help="identify parameters from measurements (CSV)")
    fit.add_argument("experiment", choices=EXPERIMENTS)
    fit.add_argument("files", nargs="+", metavar="FILE", help="measurement CSV file(s)")
    fit.add_argument("--out", type=Path, metavar="DIR",
                     help="output folder (default: results/fit-EXPERIMENT)")
    fit.add_argument("--model", metavar="FILE",
                     help="base parameter file for everything not fitted (default: reference wire)")
    fit.set_defaults(handler=_fit)

    synth = commands.add_parser("synth", help="synthetic measurement CSV from a parameter file")
    synth.add_argument("experiment", choices=EXPERIMENTS)
    synth.add_argument("--out", type=Path, required=True, metavar="FILE", help="CSV file to write")
    synth.add_argument("--model", metavar="FILE", help="parameter file (default: reference wire)")
    synth.add_argument("--loads", type=number_list, metavar="KG,KG,...",
                       help="constant-load: the loads [kg] (default 0.0032,0.05,0.15,0.25); "
                            "constant-temperature: the load path (default 0,0.1,0.03,0.2,0.03,0.3)")
    synth.add_argument("--t-min", type=finite_number, default=10.0, help="sweep start [degC]")
    synth.add_argument("--t-max", type=finite_number, default=110.0, help="sweep end [degC]")
    synth.add_argument("--t-step", type=positive_number, default=1.0, help="sweep step [K]")
    synth.add_argument("--temperature", type=finite_number, default=20.0,
                       help="constant-temperature: the temperature [degC]")
    synth.add_argument("--load-step", type=positive_number, default=0.005,
                       help="constant-temperature: load sampling step [kg]")
    synth.add_argument("--noise-ohm", type=nonnegative_number, default=0.0,
                       help="resistance noise sigma [ohm]")
    synth.add_argument("--noise-K", type=nonnegative_number, default=0.0,
                       help="temperature noise sigma [K]")
    synth.add_argument("--seed", type=int, default=0, help="random seed")
    synth.add_argument("--no-direction", action="store_true",
                       help="constant-load: leave out the direction column")
    synth.set_defaults(handler=_synth)
