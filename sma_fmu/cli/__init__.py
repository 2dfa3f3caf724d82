"""Command line ``sma-fmu``: thin wrappers; each flag maps onto one API argument.

One module per group of commands (model, fmus, cosim, analysis, loops, export, check,
identification, studies, bench, examples);
each has ``register(commands)``. Every failure is one line ``sma-fmu: error: ...`` on stderr
with exit status 2 (``validate`` and ``check`` exit 1 when a file fails); a Ctrl-C is one
line ``sma-fmu: interrupted``, exit status 130; no traceback, ever. The modules import what a
command's work needs inside its handler, after its input files were found: ``--version``
and a wrong path answer at once.
"""

import sys

from sma_fmu import __version__

from . import (analysis, bench, check, cosim, examples, export, fmus, identification, loops,
               model, studies)
from .arguments import Parser, fail

__all__ = ["main", "build_parser", "COMMAND_GROUPS", "INTERRUPTED"]

INTERRUPTED = 130   # the exit status after a Ctrl-C (128 + SIGINT), as shells report it

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


def _message(error, command):
    instance = sys.modules.get("sma_fmu.fmi.driving.instance")   # imported if an FMU ran
    if isinstance(error, ValueError) or (instance and isinstance(error, instance.FmuError)):
        return str(error)
    if isinstance(error, ModuleNotFoundError) and error.name:
        from sma_fmu.console.extras import extra_of_module
        module = error.name.partition(".")[0]
        extra = extra_of_module(module)
        if extra:
            return f'{command} needs {module}, which is not installed: pip install "sma-fmu[{extra}]"'
    if isinstance(error, OSError):
        where = f"{error.filename}: " if error.filename else ""
        return f"{where}{error.strerror or error}"
    if isinstance(error, RecursionError):
        return f"input nested too deeply ({error})"
    if isinstance(error, MemoryError):
        return "out of memory"
    return f"internal error, please report it: {type(error).__name__}: {error}"


def main(argv=None):
    """Run the command line; returns the exit status (130 after a Ctrl-C). Called with no
    ``argv`` (the ``sma-fmu`` process), it ignores Ctrl-C once the command is over."""
    args = build_parser().parse_args(argv)
    from sma_fmu.console import interrupts, progress

    previous = progress.configure(quiet=getattr(args, "quiet", False), notes=True)
    try:
        with interrupts.handle_interrupts(then_ignore=argv is None):
            try:
                return args.handler(args)
            except (Exception, KeyboardInterrupt) as error:  # noqa: BLE001 - never a traceback
                if interrupts.seen():   # whatever the Ctrl-C caused on its way out
                    placed = interrupts.outputs_placed()   # too late to undo: said so
                    print("sma-fmu: interrupted" + (f" after writing {', '.join(placed)} in full"
                                                    if placed else ""), file=sys.stderr)
                    return INTERRUPTED
                return fail(_message(error, args.command))
    finally:
        progress.configure(*previous)
