"""Compliance check command: ``sma-fmu check FILE...`` for FMUs, SSP packages and containers."""
from pathlib import Path

__all__ = ["register"]


def _check(args):
    from sma_fmu.fmi.packaging.platforms import platform_results
    from sma_fmu.systems.check import CheckResult, archive_results, check_files, format_result

    missing = [str(path) for path in args.files if not Path(path).is_file()]
    if missing:
        raise ValueError(f"{missing[0]}: no such file")
    passed = True
    for path in args.files:
        passed = check_files([path]) and passed
        if archive_results(path):  # failed above (not an FMU or SSP, unsafe): nothing else reads it
            continue
        for check, status, detail in platform_results(path):  # where the FMU runs, and how well
            print(format_result(CheckResult(str(path), check, status, detail)))
            passed = passed and status != "FAIL"
    return 0 if passed else 1


def register(commands):
    """Add ``check`` to the ``commands`` subparsers."""
    check = commands.add_parser(
        "check", help="compliance checks of FMUs, SSPs, containers (exit 1 if any fails)",
        description="Per file: fmpy's validation, fmu-manipulation-toolbox's FMI checker, a short "
                    "run in a C host (libcosim) and a state save/restore round trip (the FMUs "
                    "of an SSP one by one; its C-host run is of the whole system), and per "
                    "platform the FMU lists: whether its binary is the C front, or what "
                    "is degraded without it. One line per check; exit status 1 when any "
                    "check fails.")
    check.add_argument("files", nargs="+", type=Path, metavar="FILE",
                       help="an .fmu (an FMU or a container) or an .ssp")
    check.set_defaults(handler=_check)
