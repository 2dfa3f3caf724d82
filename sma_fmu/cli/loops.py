"""Loops command: R over T for one load, the major loop and the minor loops of a history."""
from pathlib import Path

from .arguments import nonnegative_number, number_list, positive_number

__all__ = ["register"]

# two minor loops nested in a major-loop branch; the first is wiped out by the second
DEFAULT_HISTORY = "20,120,52,76,60,70,56,74,20"


def _checked(option, text, check, *arguments):
    """``check(*arguments)``; a ``ValueError`` becomes one naming ``option`` and its value."""
    try:
        return check(*arguments)
    except ValueError as error:
        message = str(error)
        if not message.startswith(text):
            message = f"{text}: {message}"
        raise ValueError(f"{option} {message}") from None


def _count(number, noun):
    return f"{number} {noun}{'' if number == 1 else 's'}"


def _loops(args):
    from sma_fmu.analysis.minor_loop_figure import (check_history, check_load, check_step,
                                                    closure_rows, reversal_rows, trace_history,
                                                    write_loops)
    from sma_fmu.files.output_folder import check_folder
    from sma_fmu.wire.parameter_file import load_parameter_set

    check_folder(args.out)
    model = "the reference wire" if args.model is None else str(Path(args.model))
    params = _checked("--model", model, lambda: load_parameter_set(args.model).params)
    history_text = ",".join(f"{value:.15g}" for value in args.history)
    _checked("--load", f"{args.load:.15g}", check_load, args.load, params)
    points = _checked("--history", history_text, check_history, args.history, params)
    _checked("--step-K", f"{args.step_K:.15g}", check_step, points, args.step_K)
    trace = _checked("--history", history_text, trace_history, params, args.load, points,
                     args.step_K)
    csv_path, png_path = write_loops(trace, params, args.out)
    reversals, closed = len(reversal_rows(trace)), len(closure_rows(trace))
    print(f"loops: load {trace.load:g} kg, history {' -> '.join(f'{t:g}' for t in points)} degC: "
          f"{trace.T.size} samples, {_count(reversals, 'reversal point')}, "
          f"{_count(closed, 'loop')} closed")
    print(f"written: {csv_path}, {png_path}")
    return 0


def register(commands):
    """Add ``loops`` to the ``commands`` subparsers."""
    loops = commands.add_parser(
        "loops", help="R over T for one load: the major loop and the minor loops of a temperature "
                      "history (return-point memory), loops.png and loops.csv")
    loops.add_argument("--load", type=nonnegative_number, default=0.05, metavar="KG",
                       help="hung mass [kg]")
    loops.add_argument("--model", metavar="FILE",
                       help="parameter file (default: the shipped reference_wire.toml)")
    loops.add_argument("--history", type=number_list, default=DEFAULT_HISTORY, metavar="T1,T2,...",
                       help="temperature turning points [degC], swept in order by the plant "
                            "(mode continuous); the first at or above thermal.T_room, the "
                            "others above it")
    loops.add_argument("--step-K", dest="step_K", type=positive_number, default=0.1, metavar="K",
                       help="largest temperature step of the sweep [K], at least 1e-6")
    loops.add_argument("--out", type=Path, default=Path("results") / "loops", metavar="DIR",
                       help="output folder")
    loops.set_defaults(handler=_loops)
