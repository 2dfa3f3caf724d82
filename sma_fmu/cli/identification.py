"""Identification commands: fit (parameters from measurements), synth (synthetic measurements).

Experiments: constant-load, constant-temperature (resistance, the paper's two) and isobaric
(strain under constant load through thermal cycles, ASTM E3097-style lab data)."""
from pathlib import Path

from sma_fmu.console.extras import require
from sma_fmu.identification.limits import MAX_LOAD_KG, MAX_STRESS_MPA

from .arguments import (add_quiet_argument, bounded_integer, bounded_number, column_rename,
                        finite_number, number_list, require_inputs)

__all__ = ["register"]

EXPERIMENTS = ("constant-load", "constant-temperature", "isobaric")
_ISOBARIC_ONLY = ("load", "stress", "residual_strain", "reference_length", "cycles", "lag",
                  "stages", "keep_outliers", "widths", "centre_law", "column")
_SYNTH_ISOBARIC_ONLY = ("points", "cycles", "rate", "dwell", "noise_strain", "drift", "strain_unit",
                        "lag_s", "drift_decay", "first_cycle_shift")
_COLUMN_HELP = ("read the file's column OLD as NEW, a name the reader knows (strain_percent, "
                "extension_mm, temperature_C, stress_MPa, ...), without editing the file; "
                "repeat for more")
_T_RANGE = {"isobaric": (15.0, 130.0)}  # others: (10, 110)
# choice: synth's limits, wide for any real test file and checked before anything is made
MAX_ROWS = 1_000_000          # rows (or samples) one synth call may write
MAX_NOISE_OHM, MAX_NOISE_K, MAX_NOISE_STRAIN = 10.0, 50.0, 0.1


def _only_for(args, names, experiment, command):
    for name in names:
        value = getattr(args, name)
        if value not in (None, False):
            raise ValueError(f"{command}: --{name.replace('_', '-')} applies to {experiment} only")


def _check_fit_loads(args):
    """--load in [0, MAX_LOAD_KG] kg, --stress in (0, MAX_STRESS_MPA] MPa."""
    for name, values, low_open, high, unit in (("--load", args.load, False, MAX_LOAD_KG, "kg"),
                                               ("--stress", args.stress, True, MAX_STRESS_MPA,
                                                "MPa")):
        for value in values or []:
            if not ((value > 0.0) if low_open else (value >= 0.0)) or value > high:
                raise ValueError(f"fit: {name} {value!r} {unit} is outside "
                                 f"{'(' if low_open else '['}0, {high:g}] {unit}")


NOT_CONVERGED = 3     # exit status of a fit whose solver did not converge


def _meter():
    """A progress bar of the fit's model evaluations on stderr, silent when it is no terminal."""
    from tqdm import tqdm
    return tqdm(desc="fit", unit=" evaluations", disable=None, leave=False, dynamic_ncols=True)


def _fit_isobaric(args, out):
    import sys
    from sma_fmu.identification.coverage import coverage_lines
    from sma_fmu.identification.isobaric.runner import format_isobaric_report, run_isobaric_fit
    from sma_fmu.console.progress import echo
    _check_fit_loads(args)
    report = run_isobaric_fit(args.files, out, args.load, args.stress, args.model,
                              args.residual_strain or "per-cycle", args.reference_length,
                              progress=echo, cycles=args.cycles,
                              lag=args.lag or "auto", stages=args.stages or 2,
                              outliers="keep" if args.keep_outliers else "leave-out",
                              widths=args.widths or "auto", meter=_meter,
                              centre_law=args.centre_law or "linear",
                              renames=args.column)
    print(format_isobaric_report(report))
    print("\n".join(coverage_lines(report)))
    print(f"written: {out}/identified.toml, report.json, transformation_temperatures.md/.csv, "
          f"figures")
    solver = report["solver"]
    if not solver["converged"]:
        print(f"sma-fmu: the fit did not converge: {solver['message']} after "
              f"{solver['evaluations']} evaluations; identified.toml is marked 'not converged' "
              f"(exit {NOT_CONVERGED})", file=sys.stderr)
        return NOT_CONVERGED
    return 0


def _fit(args):
    if args.experiment == "isobaric":
        _check_fit_loads(args)
    else:
        _only_for(args, _ISOBARIC_ONLY, "isobaric", "fit")
    from sma_fmu.identification.workbook import expand_workbooks, file_part
    require_inputs(*((file_part(path), "file") for path in args.files),
                   (args.model, "parameter file"))
    require("fit", "fit")
    from sma_fmu.console.progress import echo
    from sma_fmu.identification.runner import format_report, run_fit
    out = args.out or Path("results") / f"fit-{args.experiment}"
    if args.experiment == "isobaric":
        args.files = expand_workbooks(args.files)
        return _fit_isobaric(args, out)
    _only_for(args, _ISOBARIC_ONLY, "isobaric", "fit")
    report = run_fit(args.experiment, args.files, out, args.model, progress=echo)
    print(format_report(report))
    print(f"written: {out}/identified.toml, report.json, figures")
    return 0


def _synth_isobaric(args, params, t_min, t_max):
    import dataclasses

    from sma_fmu.identification.isobaric.synthetic import (IsobaricProgramme, isobaric_table,
                                                           isobaric_text, stress_of_load)
    from sma_fmu.files.output_folder import staged_folder, write_file
    loads = args.loads or [0.15]
    programme = IsobaricProgramme(
        t_low=t_min, t_high=t_max, rate=args.rate or 10.0, cycles=args.cycles or 3,
        dwell=60.0 if args.dwell is None else args.dwell, points=args.points or 3000,
        noise_K=3.0 if args.noise_K is None else args.noise_K,
        noise_strain=1e-4 if args.noise_strain is None else args.noise_strain,
        noise_ohm=0.05 if args.noise_ohm is None else args.noise_ohm,
        residual=1.5e-3 if args.drift is None else args.drift, seed=args.seed,
        decay=0.5 if args.drift_decay is None else args.drift_decay,
        lag_s=args.lag_s or 0.0, first_shift_K=args.first_cycle_shift or 0.0)
    texts = {}
    for index, load in enumerate(loads):
        run = dataclasses.replace(programme, seed=programme.seed + index)
        columns, truth = isobaric_table(params, load, run, args.strain_unit or "percent",
                                        not args.no_time, args.resistance)
        header = [
            "Isobaric thermal cycling (ASTM E3097-style), synthetic: sma-fmu synth isobaric",
            f"wire: {args.model or 'reference wire'}; diameter {params.diameter * 1e3:g} mm",
            f"load: {load:g} kg (stress {stress_of_load(load, params.diameter):.4g} MPa)",
            f"reference length: {params.x0:g} m (strain = length / reference - 1)",
            f"programme: {run.t_low:g} -> {run.t_high:g} degC at {run.rate:g} K/min, "
            f"{run.cycles} cycles, dwell {run.dwell:g} s, {run.points} samples",
            f"noise: temperature {run.noise_K:g} K, strain {run.noise_strain:g}, resistance "
            f"{run.noise_ohm:g} ohm; seed {run.seed}",
            f"first cycle: transformation {run.first_shift_K:g} K hotter than the rest",
            f"wire lag behind the thermocouple: {run.lag_s:g} s = {truth['lag_samples']:.6g} "
            f"samples (first order)",
            "true residual-strain levels: " + ", ".join(f"{v:.6g}" for v in truth["offsets"])]
        texts[f"isobaric-{load:g}kg.csv"] = (isobaric_text(columns, header), load, run.points)
    if len(loads) == 1:
        (text, load, points), = texts.values()
        write_file(args.out, text)
        print(f"{args.out}: {points} rows (isobaric at {load:g} kg, seed {args.seed})")
        return 0
    with staged_folder(args.out) as folder:
        for name, (text, _, _) in texts.items():
            (folder / name).write_text(text, encoding="utf-8")
    print(f"{args.out}: {', '.join(texts)} (isobaric, seed {args.seed} onwards)")
    return 0


def _check_synth_size(args, params, t_min, t_max):
    """Loads inside the model's validity, temperatures above absolute zero and up to T_max,
    and at most MAX_ROWS rows, all before anything is computed."""
    for load in args.loads or []:
        if not 0.0 <= load <= params.load_max:
            raise ValueError(f"synth: --loads {load!r} kg is outside [0, {params.load_max:.4g}] kg, "
                             "the model's validity range (validity.stress_max)")
    for name, value in (("--t-min", t_min), ("--t-max", t_max), ("--temperature", args.temperature)):
        if not -273.15 < value <= params.T_max:
            raise ValueError(f"synth: {name} {value!r} degC is outside (-273.15, {params.T_max:g}] degC")
    if args.experiment == "isobaric":
        rows = len(args.loads or [0]) * (args.points or 3000)
        what = f"--points {args.points or 3000} per load"
    elif args.experiment == "constant-load":
        rows = len(args.loads or [0] * 4) * 2 * (abs(t_max - t_min) / args.t_step + 1)
        what = f"--t-step {args.t_step!r} K over {t_min!r}..{t_max!r} degC"
    else:
        path = args.loads or [0.0, 0.1, 0.03, 0.2, 0.03, 0.3]
        rows = sum(abs(b - a) for a, b in zip(path, path[1:])) / args.load_step + len(path)
        what = f"--load-step {args.load_step!r} kg along the load path"
    if rows > MAX_ROWS:
        raise ValueError(f"synth: {what} would make about {rows:.3g} rows; at most {MAX_ROWS:,}")


def _synth(args):
    require_inputs((args.model, "parameter file"))
    if args.experiment == "isobaric":
        require("fit", "synth isobaric")
    from sma_fmu.identification.synthetic import (constant_load_rows, constant_temperature_rows,
                                                  write_rows)
    from sma_fmu.wire.parameter_file import load_parameter_set
    params = load_parameter_set(args.model).params
    t_min, t_max = _T_RANGE.get(args.experiment, (10.0, 110.0))
    t_min = t_min if args.t_min is None else args.t_min
    t_max = t_max if args.t_max is None else args.t_max
    _check_synth_size(args, params, t_min, t_max)
    if args.experiment == "isobaric":
        return _synth_isobaric(args, params, t_min, t_max)
    _only_for(args, _SYNTH_ISOBARIC_ONLY + ("no_time", "resistance"), "isobaric", "synth")
    noise_ohm = args.noise_ohm or 0.0
    noise_k = args.noise_K or 0.0
    if args.experiment == "constant-load":
        rows = constant_load_rows(params, args.loads or [0.0032, 0.05, 0.15, 0.25], t_min,
                                  t_max, args.t_step, noise_ohm, noise_k, args.seed,
                                  not args.no_direction)
    else:
        rows = constant_temperature_rows(params, args.temperature,
                                         args.loads or [0.0, 0.1, 0.03, 0.2, 0.03, 0.3],
                                         args.load_step, noise_ohm, noise_k, args.seed)
    write_rows(args.out, rows)
    print(f"{args.out}: {len(rows)} rows ({args.experiment}, seed {args.seed})")
    return 0


def _predict(args):
    from sma_fmu.identification.workbook import file_part
    require_inputs((file_part(args.file), "file"), (args.model, "parameter file"))
    require("fit", "predict")
    from sma_fmu.identification.isobaric.predict_runner import (format_predict_report,
                                                                run_isobaric_predict)
    for name, value, high, unit in (("--load", args.load, MAX_LOAD_KG, "kg"),
                                    ("--stress", args.stress, MAX_STRESS_MPA, "MPa")):
        if value is not None and not 0.0 < value <= high:
            raise ValueError(f"predict: {name} {value!r} {unit} is outside (0, {high:g}] {unit}")
    out = args.out or Path("results") / "predict-isobaric"
    report = run_isobaric_predict(args.file, out, args.model, args.load, args.stress,
                                  args.reference_length, args.lag, args.column)
    print(format_predict_report(report))
    print(f"written: {out}/report.json, predicted.csv, predict_isobaric.png")
    return 0


def register(commands):
    """Add ``fit``, ``predict`` and ``synth`` to the ``commands`` subparsers."""
    fit = commands.add_parser("fit", help="identify parameters from measurements (CSV)")
    fit.add_argument("experiment", choices=EXPERIMENTS)
    fit.add_argument("files", nargs="+", metavar="FILE",
                     help="measurement CSV file(s); isobaric also an Excel workbook: BOOK.xlsx "
                          "(each sheet a file) or BOOK.xlsx#SHEET")
    fit.add_argument("--out", type=Path, metavar="DIR",
                     help="output folder (default: results/fit-EXPERIMENT)")
    fit.add_argument("--model", metavar="FILE",
                     help="base parameter file for everything not fitted (default: reference wire)")
    fit.add_argument("--load", type=number_list, metavar="KG[,KG...]",
                     help=f"isobaric: the hung mass [kg] in [0, {MAX_LOAD_KG:g}], one for all files "
                          "or one per file (default: the file header's 'load: ... kg')")
    fit.add_argument("--stress", type=number_list, metavar="MPA[,MPA...]",
                     help=f"isobaric: the stress [MPa] in (0, {MAX_STRESS_MPA:g}] instead of "
                          "--load (uses the wire diameter)")
    fit.add_argument("--residual-strain", choices=("per-cycle", "none"),
                     help="isobaric: a strain offset per residual-strain level (each cycle may "
                          "leave strain behind), or one per file (default: per-cycle)")
    fit.add_argument("--cycles", metavar="A:B",
                     help="isobaric: the cycles to fit, numbered from 1 as found in the file: "
                          "'5:' drops the first four (unstabilised) cycles, '3:10', ':20', '4' "
                          "(default: all)")
    fit.add_argument("--lag", choices=("auto", "fit", "none"),
                     help="isobaric: fit the wire's first-order lag behind the thermocouple (in "
                          "seconds, or samples without a time column), assume none, or auto: "
                          "fit it when every file holds two complete cycles or more crossing "
                          "the transformation at rates that differ by 25 %% or more (at one "
                          "rate a lag cannot be told from a wider hysteresis) (default: auto)")
    fit.add_argument("--stages", type=int, choices=(1, 2),
                     help="isobaric: transformation stages, each a logistic with its own centres "
                          "and widths on heating and cooling; 2 fits the second from the "
                          "one-stage fit (default: 2)")
    fit.add_argument("--widths", choices=("auto", "shared", "separate"),
                     help="isobaric: one transition width (nu) for heating and cooling, one each "
                          "(nu_h, nu_c), or auto: one, then one each kept only when it lowers "
                          "the cost by 1 %% (default: auto)")
    fit.add_argument("--centre-law", choices=("linear", "clausius-clapeyron"),
                     help="isobaric: hysteresis centres linear in the load, or with a load slope "
                          "that follows the transformation strain s(sigma) (Clausius-Clapeyron; "
                          "the shares cc_share_h, cc_share_c are fitted with three stresses or "
                          "more, else kept from --model) (default: linear)")
    fit.add_argument("--keep-outliers", action="store_true",
                     help="isobaric: keep cycles whose strain residual RMS exceeds 3x the median "
                          "cycle's (default: they are named and left out)")
    fit.add_argument("--reference-length", type=bounded_number(0.0, 100.0, "m"), metavar="M",
                     help="isobaric: length the strain is measured from [m] (default: the base "
                          "file's x0)")
    fit.add_argument("--column", type=column_rename, action="append", metavar="NEW=OLD",
                     help=f"isobaric: {_COLUMN_HELP}")
    add_quiet_argument(fit)
    fit.set_defaults(handler=_fit)

    predict = commands.add_parser(
        "predict", help="run the plant runtime (the FMU's code) through a lab file's measured "
                        "temperature and compare the strain")
    predict.add_argument("experiment", choices=("isobaric",))
    predict.add_argument("file", metavar="FILE",
                         help="isobaric measurement file (CSV, or a workbook's sheet: "
                              "BOOK.xlsx#SHEET)")
    predict.add_argument("--model", required=True, metavar="PARAMS",
                         help="parameter file, e.g. the identified.toml of sma-fmu fit isobaric")
    loads = predict.add_mutually_exclusive_group()
    loads.add_argument("--stress", type=finite_number, metavar="MPA",
                       help="the file's stress [MPa] (default: its stress column or header)")
    loads.add_argument("--load", type=finite_number, metavar="KG",
                       help="the file's hung mass [kg] instead of --stress")
    predict.add_argument("--reference-length", type=bounded_number(0.0, 100.0, "m"), metavar="M",
                         help="length the strain is measured from [m] (default: the model's x0)")
    predict.add_argument("--lag", type=bounded_number(0.0, 1e6, closed=True), default=0.0,
                         metavar="TAU",
                         help="the wire's first-order lag behind the thermocouple [s, or samples "
                              "without a time column], as fit isobaric reports it")
    predict.add_argument("--column", type=column_rename, action="append", metavar="NEW=OLD",
                         help=_COLUMN_HELP)
    predict.add_argument("--out", type=Path, metavar="DIR",
                         help="output folder (default: results/predict-isobaric)")
    add_quiet_argument(predict)
    predict.set_defaults(handler=_predict)

    synth = commands.add_parser("synth", help="synthetic measurement CSV from a parameter file")
    synth.add_argument("experiment", choices=EXPERIMENTS)
    synth.add_argument("--out", type=Path, required=True, metavar="FILE", help="CSV file to write")
    synth.add_argument("--model", metavar="FILE", help="parameter file (default: reference wire)")
    synth.add_argument("--loads", type=number_list, metavar="KG,KG,...",
                       help="constant-load: the loads [kg] (default 0.0032,0.05,0.15,0.25); "
                            "constant-temperature: the load path (default 0,0.1,0.03,0.2,0.03,0.3); "
                            "isobaric: one file per load (default 0.15; several: --out is a folder)")
    synth.add_argument("--t-min", type=finite_number,
                       help="sweep start [degC] (default: 10; isobaric 15)")
    synth.add_argument("--t-max", type=finite_number,
                       help="sweep end [degC] (default: 110; isobaric 130)")
    synth.add_argument("--t-step", type=bounded_number(0.0, 100.0, "K"), default=1.0, help="sweep step [K]")
    synth.add_argument("--temperature", type=finite_number, default=20.0,
                       help="constant-temperature: the temperature [degC]")
    synth.add_argument("--load-step", type=bounded_number(0.0, 1.0, "kg"), default=0.005,
                       help="constant-temperature: load sampling step [kg]")
    synth.add_argument("--noise-ohm", type=bounded_number(0.0, MAX_NOISE_OHM, "ohm", closed=True),
                       help="resistance noise sigma [ohm] (default: 0; isobaric 0.05)")
    synth.add_argument("--noise-K", type=bounded_number(0.0, MAX_NOISE_K, "K", closed=True),
                       help="temperature noise sigma [K] (default: 0; isobaric 3)")
    synth.add_argument("--noise-strain", type=bounded_number(0.0, MAX_NOISE_STRAIN, closed=True),
                       help="isobaric: strain noise sigma [1] (default: 1e-4)")
    synth.add_argument("--points", type=bounded_integer(10, MAX_ROWS),
                       help="isobaric: samples per file, evenly spaced in time (default: 3000)")
    synth.add_argument("--cycles", type=bounded_integer(1, 1000), help="isobaric: thermal cycles (default: 3)")
    synth.add_argument("--rate", type=bounded_number(0.0, 1e4, "K/min"), help="isobaric: ramp rate [K/min] (default: 10)")
    synth.add_argument("--dwell", type=bounded_number(0.0, 1e5, "s", closed=True),
                       help="isobaric: hold at each end [s] (default: 60)")
    synth.add_argument("--drift", type=bounded_number(0.0, 0.1, closed=True),
                       help="isobaric: residual strain of the first cycle [1], halving each "
                            "cycle (default: 1.5e-3)")
    synth.add_argument("--drift-decay", type=bounded_number(0.0, 1.0, closed=True),
                       help="isobaric: ratio of one cycle's residual strain to the previous "
                            "(default: 0.5; 0.97 drifts slowly over 100 cycles)")
    synth.add_argument("--lag-s", type=bounded_number(0.0, 1e4, "s", closed=True),
                       help="isobaric: time constant of the wire's lag behind the thermocouple "
                            "[s] (default: 0). A lab-like file: --cycles 100 --points 26000 "
                            "--dwell 0 --rate 20 --t-min 20 --t-max 115 --noise-K 10 --lag-s 20 "
                            "--drift 1e-3 --drift-decay 0.97 --no-time")
    synth.add_argument("--first-cycle-shift", type=bounded_number(0.0, 100.0, "K", closed=True),
                       help="isobaric: the first cycle's transformation this much hotter [K], a "
                            "first cycle unlike the rest (default: 0)")
    synth.add_argument("--strain-unit", choices=("percent", "fraction", "length"),
                       help="isobaric: strain_percent, strain or length_m column (default: percent)")
    synth.add_argument("--no-time", action="store_true", help="isobaric: leave out the time column")
    synth.add_argument("--resistance", action="store_true",
                       help="isobaric: add a resistance_ohm column")
    synth.add_argument("--seed", type=bounded_integer(0, 2 ** 32 - 1), default=0, help="random seed")
    synth.add_argument("--no-direction", action="store_true",
                       help="constant-load: leave out the direction column")
    synth.set_defaults(handler=_synth)
