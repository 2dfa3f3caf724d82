"""Command line ``sma-fmu``: thin wrappers; each flag maps onto one API argument.

The model commands print ``name = value unit`` lines, or one JSON object with ``--json``.
Errors go to stderr as ``sma-fmu: error: ...`` with exit status 2; ``validate`` exits 1
when an FMU has problems.
"""
import argparse
import json
import sys

from pathlib import Path

from . import fmu_build
from .fmu_instance import FmuError
from .parameter_file import load_parameter_set
from .runtime.checks import direction_name, direction_sign, require_finite
from .runtime.constant_length import load_temperature_slope
from .runtime.constant_load import constant_load_fractions
from .runtime.phases import length_of, resistance_of
from .runtime.sensing import sense_temperature

__all__ = ["main", "build_parser"]


def _report(rows, as_json):
    """Print rows of (name, value, unit) as text lines or one JSON object."""
    if as_json:
        print(json.dumps({name: value for name, value, _ in rows}))
        return
    for name, value, unit in rows:
        text = f"{value:.6g}" if isinstance(value, float) else str(value)
        print(f"{name} = {text}{' ' + unit if unit else ''}")


def _number(text):
    """argparse type: a finite float (NaN/inf rejected with the value in the message)."""
    try:
        return require_finite("value", float(text))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}") from None


def _cmd_lattice(args, parameter_set):
    lattice = parameter_set.params.lattice
    return [("N", lattice.N, ""), ("x_P", lattice.x_P, "m"), ("N_l", lattice.N_l, ""),
            ("N_S", lattice.N_S, "")]


def _cmd_resistance(args, parameter_set):
    params = parameter_set.params
    fractions = constant_load_fractions(args.temperature, args.load, args.direction, params)
    return [("temperature", args.temperature, "degC"), ("load", args.load, "kg"),
            ("direction", direction_name(args.direction), ""),
            ("R", resistance_of(fractions, params), "ohm"),
            ("xi_P", fractions.xi_P, ""), ("xi_M", fractions.xi_M, ""),
            ("xi_F", fractions.xi_F, ""), ("x", length_of(fractions, params), "m")]


def _cmd_sense(args, parameter_set):
    sensed = sense_temperature(args.resistance, args.load, args.direction, parameter_set.params)
    return [("resistance", args.resistance, "ohm"), ("load", args.load, "kg"),
            ("direction", direction_name(args.direction), ""),
            ("T", sensed.temperature, "degC"), ("saturated", sensed.saturated, "")]


def _cmd_constant_length(args, parameter_set):
    slope = load_temperature_slope(args.xi_p, args.xi_m, args.xi_f, parameter_set.params)
    return [("xi_P", args.xi_p, ""), ("xi_M", args.xi_m, ""), ("xi_F", args.xi_f, ""),
            ("df_dT", slope, "kg/K")]


def _direction(text):
    """argparse type: "heating" or "cooling" -> +1 or -1."""
    try:
        return direction_sign(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def _model_command(compute):
    """Handler that loads the parameter file, computes rows and prints them."""
    def handler(args):
        _report(compute(args, load_parameter_set(args.model)), args.json)
        return 0
    return handler


def _cmd_build(args):
    paths = fmu_build.build_fmus(args.out, args.model)
    for name, path in paths.items():
        print(f"{name}: {path}")
    return 0


def _cmd_validate(args):
    paths = args.fmus or list(fmu_build.default_fmu_paths(args.out).values())
    failed = False
    for path, problems in fmu_build.validate_fmus(paths).items():
        print(f"{path}: {'valid (fmpy: no problems)' if not problems else f'{len(problems)} problem(s)'}")
        for problem in problems:
            print(f"  - {problem}")
        failed = failed or bool(problems)
    return 1 if failed else 0


def _cmd_run(args):
    from .runner import timed_run
    from .scenario import resolve_scenarios
    paths = resolve_scenarios(args.scenarios, everything=args.all)
    timed_run(paths, args.out, args.path, args.fmus)
    return 0


def _cmd_fit(args):
    from .fit_runner import format_report, run_fit
    out = args.out or Path("results") / f"fit-{args.experiment}"
    report = run_fit(args.experiment, args.files, out, args.model)
    print(format_report(report))
    print(f"written: {out}/identified.toml, report.json, figures")
    return 0


def _number_list(text):
    """argparse type: comma-separated finite numbers."""
    try:
        return [require_finite("value", float(item)) for item in text.split(",") if item.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}") from None


def _cmd_synth(args):
    from .synthetic import constant_load_rows, constant_temperature_rows, write_rows
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


def _cmd_bench(args):
    from .benchmark import main as bench_main
    return bench_main(args.out, args.runs)


def _add_direction(parser):
    parser.add_argument("--direction", required=True, type=_direction,
                        metavar="heating|cooling", help="sign of dT/dt")


def build_parser():
    """The argparse parser of ``sma-fmu``."""
    parser = argparse.ArgumentParser(
        prog="sma-fmu", description="SMA wire actuator model, compensator and FMUs.")
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--model", metavar="FILE",
                        help="parameter file (default: models/reference_wire.toml)")
    common.add_argument("--json", action="store_true", help="print one JSON object")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    lattice = commands.add_parser("lattice", parents=[common],
                                  help="lattice constants N, x_P, N_l, N_S")
    lattice.set_defaults(handler=_model_command(_cmd_lattice))

    resistance = commands.add_parser("resistance", parents=[common],
                                     help="resistance, fractions and length at T, load, direction")
    resistance.add_argument("--temperature", required=True, type=_number, metavar="C",
                            help="wire temperature [degC]")
    resistance.add_argument("--load", required=True, type=_number, metavar="KG",
                            help="hung mass [kg]")
    _add_direction(resistance)
    resistance.set_defaults(handler=_model_command(_cmd_resistance))

    sense = commands.add_parser("sense", parents=[common],
                                help="temperature from resistance (inverse model)")
    sense.add_argument("--resistance", required=True, type=_number, metavar="OHM",
                       help="wire resistance [ohm]")
    sense.add_argument("--load", required=True, type=_number, metavar="KG", help="hung mass [kg]")
    _add_direction(sense)
    sense.set_defaults(handler=_model_command(_cmd_sense))

    length = commands.add_parser("constant-length", parents=[common],
                                 help="(df/dT)_x of a wire held at constant length [kg/K]")
    length.add_argument("--xi-p", required=True, type=_number, help="P fraction [1]")
    length.add_argument("--xi-m", required=True, type=_number, help="M fraction [1]")
    length.add_argument("--xi-f", required=True, type=_number, help="F fraction [1]")
    length.set_defaults(handler=_model_command(_cmd_constant_length))

    build = commands.add_parser("build", help="build the SmaActuator and SmaFeedforward FMUs")
    build.add_argument("--out", type=Path, default=fmu_build.DEFAULT_FMU_DIR, metavar="DIR",
                       help=f"output folder (default: {fmu_build.DEFAULT_FMU_DIR})")
    build.add_argument("--model", metavar="FILE",
                       help="parameter file the FMUs carry (default: models/reference_wire.toml)")
    build.set_defaults(handler=_cmd_build)

    validate = commands.add_parser("validate", help="validate FMUs with fmpy (exit 1 on problems)")
    validate.add_argument("fmus", nargs="*", type=Path, metavar="FMU",
                          help="FMU files (default: both FMUs in --out)")
    validate.add_argument("--out", type=Path, default=fmu_build.DEFAULT_FMU_DIR, metavar="DIR",
                          help=f"folder of the default FMUs (default: {fmu_build.DEFAULT_FMU_DIR})")
    validate.set_defaults(handler=_cmd_validate)

    run = commands.add_parser(
        "run", help="run scenarios (names, files, 'paper' or --all): CSV, metrics, figures")
    run.add_argument("scenarios", nargs="*", metavar="SCENARIO",
                     help="scenario name from scenarios/, a .toml file, or 'paper'")
    run.add_argument("--all", action="store_true", help="every scenario in scenarios/")
    run.add_argument("--out", type=Path, default=Path("results"), metavar="DIR",
                     help="output folder (default: results)")
    run.add_argument("--path", choices=("fmu", "library"), default="fmu",
                     help="fmu: the FMUs under fmpy (default); library: the steppers directly")
    run.add_argument("--fmus", type=Path, default=fmu_build.DEFAULT_FMU_DIR, metavar="DIR",
                     help=f"folder of the built FMUs (default: {fmu_build.DEFAULT_FMU_DIR})")
    run.set_defaults(handler=_cmd_run)

    fit = commands.add_parser("fit", help="identify parameters from measurements (CSV)")
    fit.add_argument("experiment", choices=("constant-load", "constant-temperature"))
    fit.add_argument("files", nargs="+", metavar="FILE", help="measurement CSV file(s)")
    fit.add_argument("--out", type=Path, metavar="DIR",
                     help="output folder (default: results/fit-EXPERIMENT)")
    fit.add_argument("--model", metavar="FILE",
                     help="base parameter file for everything not fitted (default: reference wire)")
    fit.set_defaults(handler=_cmd_fit)

    synth = commands.add_parser("synth", help="synthetic measurement CSV from a parameter file")
    synth.add_argument("experiment", choices=("constant-load", "constant-temperature"))
    synth.add_argument("--out", type=Path, required=True, metavar="FILE", help="CSV file to write")
    synth.add_argument("--model", metavar="FILE", help="parameter file (default: reference wire)")
    synth.add_argument("--loads", type=_number_list, metavar="KG,KG,...",
                       help="constant-load: the loads [kg] (default 0.0032,0.05,0.15,0.25); "
                            "constant-temperature: the load path (default 0,0.1,0.03,0.2,0.03,0.3)")
    synth.add_argument("--t-min", type=_number, default=10.0, help="sweep start [degC] (10)")
    synth.add_argument("--t-max", type=_number, default=110.0, help="sweep end [degC] (110)")
    synth.add_argument("--t-step", type=_number, default=1.0, help="sweep step [K] (1)")
    synth.add_argument("--temperature", type=_number, default=20.0,
                       help="constant-temperature: the temperature [degC] (20)")
    synth.add_argument("--load-step", type=_number, default=0.005,
                       help="constant-temperature: load sampling step [kg] (0.005)")
    synth.add_argument("--noise-ohm", type=_number, default=0.0, help="resistance noise sigma [ohm]")
    synth.add_argument("--noise-K", type=_number, default=0.0, help="temperature noise sigma [K]")
    synth.add_argument("--seed", type=int, default=0, help="random seed (0)")
    synth.add_argument("--no-direction", action="store_true",
                       help="constant-load: leave out the direction column")
    synth.set_defaults(handler=_cmd_synth)

    bench = commands.add_parser("bench", help="measure speed; print a table and write JSON")
    bench.add_argument("--out", type=Path, default=Path("results/benchmark"), metavar="DIR",
                       help="output folder (default: results/benchmark)")
    bench.add_argument("--runs", type=int, default=5, help="repetitions per measurement")
    bench.set_defaults(handler=_cmd_bench)
    return parser


def main(argv=None):
    """Run the command line; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.handler(args)
    except (ValueError, FileNotFoundError, FmuError) as error:
        print(f"sma-fmu: error: {error}", file=sys.stderr)
        return 2
