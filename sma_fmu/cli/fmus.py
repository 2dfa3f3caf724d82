"""FMU commands: build, validate."""
import sys
import warnings
from pathlib import Path

from sma_fmu.fmi.packaging.fmu_names import DEFAULT_FMU_DIR

from .arguments import add_quiet_argument, require_inputs

__all__ = ["register"]


def _build(args):
    require_inputs((args.model, "parameter file"))
    from sma_fmu.fmi.packaging import build as fmu_build   # here: every other command skips it

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        paths = fmu_build.build_fmus(args.out, args.model, native=args.native,
                                     fmi_version=args.fmi, compile=args.compile)
    for warning in caught:
        print(f"sma-fmu: warning: {warning.message}", file=sys.stderr)
    for name, path in paths.items():
        print(f"{name}: {path}")
    return 0


def _validate(args):
    from sma_fmu.fmi.packaging import build as fmu_build
    from sma_fmu.fmi.packaging.fmu_names import default_fmu_paths

    require_inputs(*((path, "FMU file") for path in args.fmus))
    paths = args.fmus or list(default_fmu_paths(args.out).values())
    failed = False
    for path, problems in fmu_build.validate_fmus(paths).items():
        print(f"{path}: {'valid (fmpy: no problems)' if not problems else f'{len(problems)} problem(s)'}")
        for problem in problems:
            print(f"  - {problem}")
        failed = failed or bool(problems)
    return 1 if failed else 0


def register(commands):
    """Add ``build`` and ``validate`` to the ``commands`` subparsers."""
    build = commands.add_parser("build", help="build the FMUs")
    build.add_argument("--out", type=Path, default=DEFAULT_FMU_DIR, metavar="DIR",
                       help="output folder")
    build.add_argument("--model", metavar="FILE",
                       help="parameter file the FMUs carry (default: the shipped reference_wire.toml)")
    build.add_argument("--native", action="store_true",
                       help="build the C family: source-code FMUs with linux64/win64/darwin64/win32 binaries, "
                            "no Python needed (default: pythonfmu)")
    build.add_argument("--fmi", type=int, choices=(2, 3), default=2, metavar="{2,3}",
                       help="FMI version (default: 2); 3 needs --native: FMI 3.0 co-simulation "
                            "FMUs (x86_64/aarch64 Linux and macOS, x86_64/x86 Windows binaries; "
                            "buildDescription.xml)")
    build.add_argument("--compile", action="store_true",
                       help="--native: compile every binary here, even where the installed "
                            "package has a prebuilt one of the same sources")
    add_quiet_argument(build)
    build.set_defaults(handler=_build)

    validate = commands.add_parser("validate", help="validate FMUs with fmpy (exit 1 on problems)")
    validate.add_argument("fmus", nargs="*", type=Path, metavar="FMU",
                          help="FMU files (default: the built FMUs in --out)")
    validate.add_argument("--out", type=Path, default=DEFAULT_FMU_DIR, metavar="DIR",
                          help="folder of the default FMUs")
    validate.set_defaults(handler=_validate)
