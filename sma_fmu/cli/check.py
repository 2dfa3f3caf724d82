"""Compliance check command: ``sma-fmu check FILE...`` for FMUs, SSP packages and containers."""
from collections import Counter
from pathlib import Path

from .arguments import add_quiet_argument

__all__ = ["register", "count_line"]

_ORDER = ("ok", "warn", "n/a", "FAIL")   # the statuses a check line starts with


def count_line(statuses, files):
    """``check: 2 files, 12 checks: 10 ok, 2 n/a, 0 FAIL`` from the statuses of every line."""
    counts = Counter(statuses)
    parts = [f"{counts[status]} {status}" for status in _ORDER if counts[status] or status == "FAIL"]
    parts += [f"{count} {status}" for status, count in sorted(counts.items()) if status not in _ORDER]
    return (f"check: {files} file{'s' if files != 1 else ''}, {sum(counts.values())} checks: "
            f"{', '.join(parts)}")


def _check(args):
    missing = [str(path) for path in args.files if not Path(path).is_file()]
    if missing:
        raise ValueError(f"{missing[0]}: no such file")
    from sma_fmu.console import progress
    from sma_fmu.console.extras import require
    require("systems", "check")
    from sma_fmu.fmi.packaging.platforms import platform_results
    from sma_fmu.systems.check import CheckResult, archive_results, check_files, format_result

    statuses = []

    def report(line):
        statuses.append(line.split(None, 1)[0])
        progress.echo(line)

    passed = True
    for path in progress.steps(args.files, "checking", unit="file"):
        passed = check_files([path], report) and passed
        if archive_results(path):  # failed above (not an FMU or SSP, unsafe): nothing else reads it
            continue
        for check, status, detail in platform_results(path):  # where the FMU runs, and how well
            report(format_result(CheckResult(str(path), check, status, detail)))
            passed = passed and status != "FAIL"
    print(count_line(statuses, len(args.files)))
    return 0 if passed else 1


def register(commands):
    """Add ``check`` to the ``commands`` subparsers."""
    check = commands.add_parser(
        "check", help="compliance checks of FMUs, SSPs, containers (exit 1 if any fails)",
        description="Per file: fmpy's validation, fmu-manipulation-toolbox's FMI checker, a short "
                    "run in a C host (libcosim) and a state save/restore round trip (the FMUs "
                    "of an SSP one by one; its C-host run is of the whole system), and per "
                    "platform the FMU lists: whether its binary is the C front, or what "
                    "is degraded without it. One line per check, then their count; exit "
                    "status 1 when any check fails.")
    check.add_argument("files", nargs="+", type=Path, metavar="FILE",
                       help="an .fmu (an FMU or a container) or an .ssp")
    add_quiet_argument(check)
    check.set_defaults(handler=_check)
