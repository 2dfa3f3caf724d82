"""Command line ``sma-fmu``: thin wrappers; each flag maps onto one API argument.

One module per group of commands (model, fmus, cosim, analysis, loops, export, check,
identification, studies, bench, examples);
each has ``register(commands)``. Every failure is one line ``sma-fmu: error: ...`` on stderr
with exit status 2 (``validate`` and ``check`` exit 1 when a file fails); no traceback, ever.
"""

from sma_fmu import __version__

from . import (analysis, bench, check, cosim, examples, export, fmus, identification, loops,
               model, studies)
from .arguments import Parser, fail

__all__ = ["main", "build_parser", "COMMAND_GROUPS"]

COMMAND_GROUPS = (model, fmus, cosim, analysis, loops, export, check, identification, studies,
                  bench, examples)


def build_parser():
    """The argparse parser of ``sma-fmu``."""
    parser = Parser(prog="sma-fmu", description="SMA wire actuator model, compensator and FMUs.")
    parser.add_argument("--version", action="version", version=f"sma-fmu {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for group in COMMAND_GROUPS:
        group.register(commands)
    return parser


def _message(error):
    from sma_fmu.fmi.driving.instance import FmuError
    if isinstance(error, (ValueError, FmuError)):
        return str(error)
    if isinstance(error, OSError):
        where = f"{error.filename}: " if error.filename else ""
        return f"{where}{error.strerror or error}"
    if isinstance(error, RecursionError):
        return f"input nested too deeply ({error})"
    if isinstance(error, MemoryError):
        return "out of memory"
    return f"internal error, please report it: {type(error).__name__}: {error}"


def main(argv=None):
    """Run the command line; returns the exit status."""
    args = build_parser().parse_args(argv)
    try:
        return args.handler(args)
    except KeyboardInterrupt:
        return fail("interrupted")
    except Exception as error:  # noqa: BLE001 - the command line never prints a traceback
        return fail(_message(error))
