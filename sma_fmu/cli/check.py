"""Compliance check command: ``sma-fmu check FILE...`` for FMUs, SSP packages and containers."""
from pathlib import Path

__all__ = ["register"]


def _check(args):
    from sma_fmu.systems.check import check_files

    return 0 if check_files(args.files) else 1


def register(commands):
    """Add ``check`` to the ``commands`` subparsers."""
    check = commands.add_parser(
        "check", help="compliance checks of FMUs, SSPs, containers (exit 1 if any fails)",
        description="Per file: fmpy's validation, fmu-manipulation-toolbox's FMI checker, a short "
                    "run in a C host (libcosim) and a state save/restore round trip (the FMUs "
                    "of an SSP one by one; its C-host run is of the whole system). One line "
                    "per check; exit status 1 when any check fails.")
    check.add_argument("files", nargs="+", type=Path, metavar="FILE",
                       help="an .fmu (an FMU or a container) or an .ssp")
    check.set_defaults(handler=_check)
