"""Examples command: list the shipped scenarios and example files, or copy them into a folder."""
from pathlib import Path

__all__ = ["register"]


def _examples(args):
    from sma_fmu.files.package_data import shipped_file, shipped_files

    names = shipped_files("examples")
    scenarios = shipped_files("scenarios", ".toml")
    if args.out is None:
        print("scenarios (sma-fmu run NAME; copy one with --out and edit it):")
        for name in scenarios:
            print(f"  {name[:-len('.toml')]:<48} {shipped_file('scenarios', name)}")
        print("examples (measurements, study specs, scripts):")
        for name in names:
            print(f"  {shipped_file('examples', name)}")
        return 0
    import shutil

    from sma_fmu.files.output_folder import staged_folder
    with staged_folder(args.out, "--out") as folder:
        for name in names:
            shutil.copyfile(shipped_file("examples", name), folder / name)
        (folder / "scenarios").mkdir()
        for name in scenarios:
            shutil.copyfile(shipped_file("scenarios", name), folder / "scenarios" / name)
        (folder / "models").mkdir()   # the wires scenarios name as ../models/NAME.toml
        for name in shipped_files("models", ".toml"):
            shutil.copyfile(shipped_file("models", name), folder / "models" / name)
    for name in names:
        print(Path(args.out) / name)
    print(f"{Path(args.out) / 'scenarios'}/: the {len(scenarios)} shipped scenarios "
          "(sma-fmu run FILE.toml runs an edited copy); models/: the wires they name")
    return 0


def register(commands):
    """Add ``examples`` to the ``commands`` subparsers."""
    examples = commands.add_parser(
        "examples", help="list the shipped scenarios and example files (measurements, study "
                         "specs, scripts), or copy them")
    examples.add_argument("--out", type=Path, metavar="DIR",
                          help="copy the examples, the scenarios into DIR/scenarios/ and the "
                               "wires they name into DIR/models/ (default: only list them)")
    examples.set_defaults(handler=_examples)
