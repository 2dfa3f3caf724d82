"""Argument parsing shared by the commands: one-line errors, defaults in --help, checked types,
and the arguments several commands take (SCENARIO... with --all, --fmus)."""
import argparse
import math
import sys
from pathlib import Path

from sma_fmu.runtime.checks import direction_sign

__all__ = ["Parser", "HelpFormatter", "finite_number", "positive_number", "nonnegative_number",
           "positive_integer", "bounded_integer", "bounded_number", "number_list", "column_rename",
           "direction", "fail", "add_scenario_arguments",
           "scenario_paths", "add_fmus_argument", "add_quiet_argument", "require_inputs"]


def require_inputs(*inputs):
    """Raise ValueError ``PATH: WHAT not found`` for the first (path, what) of ``inputs``
    whose path is given (not None) and does not exist: a command checks its input files
    before it imports what its work needs, so a wrong path is told at once."""
    for path, what in inputs:
        if path is not None and not Path(path).exists():
            raise ValueError(f"{path}: {what} not found")


def fail(message):
    """Print ``sma-fmu: error: message`` on stderr (one line); returns exit status 2."""
    text = " ".join(str(message).split()) or "unknown error"
    print(f"sma-fmu: error: {text}", file=sys.stderr)
    return 2


class HelpFormatter(argparse.HelpFormatter):
    """Help that states every option's default (except None and False, which mean 'not given')."""

    def _get_help_string(self, action):
        text = action.help or ""
        if ("%(default)" not in text and "(default" not in text and "default:" not in text
                and action.default not in (None, False, argparse.SUPPRESS)
                and action.option_strings):
            text += " (default: %(default)s)"
        return text


class Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line, ``sma-fmu: error: ...``, exit status 2.

    Options are never abbreviated: ``run --output DIR`` would otherwise be taken for
    ``--output-interval``; an unknown option is named with the command's closest ones.
    """

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", HelpFormatter)
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)

    def parse_args(self, args=None, namespace=None):
        namespace, unknown = self.parse_known_args(args, namespace)
        if unknown:
            self.error(f"unrecognized arguments: {' '.join(unknown)}"
                       f"{_closest_options(self, namespace, unknown)}")
        return namespace

    def error(self, message):
        command = self.prog.split(" ", 1)[1] + ": " if " " in self.prog else ""
        self.exit(fail(f"{command}{message} (see {self.prog} --help)"))


def _closest_options(parser, namespace, unknown):
    """``"; did you mean '--out'?"`` for the first unknown option with close names among the
    options of the (sub)command ``namespace`` was parsed by, or ``""``."""
    from sma_fmu.console.suggest import did_you_mean

    command = parser
    while command._subparsers is not None:   # the chosen command, down the sub-commands
        chooser = next(a for a in command._subparsers._group_actions
                       if isinstance(a, argparse._SubParsersAction))
        chosen = chooser.choices.get(getattr(namespace, chooser.dest, None))
        if chosen is None:
            break
        command = chosen
    options = [name for action in command._actions for name in action.option_strings]
    for word in unknown:
        if word.startswith("--"):
            hint = did_you_mean(word.partition("=")[0], options)
            if hint:
                return f"; {hint}"
    return ""


def _number(text, rule=None, rule_text=""):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    if rule is not None and not rule(value):
        raise argparse.ArgumentTypeError(f"expected a number {rule_text}, got {text!r}")
    return value


def finite_number(text):
    """argparse type: a finite float."""
    return _number(text)


def positive_number(text):
    """argparse type: a finite float > 0."""
    return _number(text, lambda v: v > 0.0, "> 0")


def nonnegative_number(text):
    """argparse type: a finite float >= 0."""
    return _number(text, lambda v: v >= 0.0, ">= 0")


def positive_integer(text):
    """argparse type: an integer >= 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text!r}")
    return value


def bounded_integer(low, high):
    """argparse type factory: a whole number in [low, high] (the range shows in the error)."""
    def convert(text):
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"expected a whole number in [{low}, {high}], got {text!r}") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"expected a whole number in [{low}, {high}], got {text!r}")
        return value
    convert.__name__ = f"whole number in [{low}, {high}]"
    return convert


def bounded_number(low, high, unit="", closed=False):
    """argparse type factory: a finite number in (low, high] [unit], or [low, high] if ``closed``."""
    interval = f"{'[' if closed else '('}{low:g}, {high:g}]"

    def convert(text):
        return _number(text, lambda v: (low <= v if closed else low < v) and v <= high,
                       f"in {interval} {unit}".rstrip())
    convert.__name__ = f"number in {interval}"
    return convert


def number_list(text):
    """argparse type: comma-separated finite numbers."""
    items = [item for item in text.split(",") if item.strip()]
    if not items:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}")
    try:
        return [_number(item) for item in items]
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"expected comma-separated finite numbers, got {text!r}") from None


def column_rename(text):
    """argparse type: ``NEW=OLD`` (a file's column OLD read under the name NEW) -> (new, old)."""
    new, mark, old = text.partition("=")
    if not mark or not new.strip() or not old.strip():
        raise argparse.ArgumentTypeError(f"expected NEW=OLD (e.g. strain_percent=Strain), got "
                                         f"{text!r}")
    return new.strip(), old


def direction(text):
    """argparse type: "heating" or "cooling" -> +1 or -1."""
    try:
        return direction_sign(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def add_scenario_arguments(parser):
    """Add ``SCENARIO...`` and ``--all`` to ``parser``; :func:`scenario_paths` reads them."""
    parser.add_argument("scenarios", nargs="*", metavar="SCENARIO",
                        help="a .toml file, the name of a shipped scenario, or 'paper'")
    parser.add_argument("--all", action="store_true", help="every shipped scenario")


def scenario_paths(args):
    """The scenario files named by the arguments of :func:`add_scenario_arguments`."""
    from sma_fmu.cosim.scenario import resolve_scenarios

    return resolve_scenarios(args.scenarios, everything=args.all)


def add_fmus_argument(parser, help_text="folder of the built FMUs"):
    """Add ``--fmus DIR`` (default: where ``sma-fmu build`` writes) to ``parser``."""
    from sma_fmu.fmi.packaging.fmu_names import DEFAULT_FMU_DIR

    parser.add_argument("--fmus", type=Path, default=DEFAULT_FMU_DIR, metavar="DIR", help=help_text)


def add_quiet_argument(parser):
    """Add ``--quiet``: no progress bars (they show only on a terminal anyway)."""
    parser.add_argument("--quiet", action="store_true",
                        help="no progress bars (shown only when stderr is a terminal)")
