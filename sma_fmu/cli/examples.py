"""Examples command: list the shipped example files, or copy them into a folder."""
import shutil
from pathlib import Path

from sma_fmu.files.package_data import shipped_file, shipped_files

__all__ = ["register"]


def _examples(args):
    names = shipped_files("examples")
    if args.out is None:
        for name in names:
            print(shipped_file("examples", name))
        return 0
    from sma_fmu.files.output_folder import staged_folder
    with staged_folder(args.out, "--out") as folder:
        for name in names:
            shutil.copyfile(shipped_file("examples", name), folder / name)
    for name in names:
        print(Path(args.out) / name)
    return 0


def register(commands):
    """Add ``examples`` to the ``commands`` subparsers."""
    examples = commands.add_parser(
        "examples", help="list the shipped example files (measurements, scripts), or copy them")
    examples.add_argument("--out", type=Path, metavar="DIR",
                          help="copy the examples into this folder (default: only list them)")
    examples.set_defaults(handler=_examples)
