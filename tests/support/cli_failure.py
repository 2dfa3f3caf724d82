"""The CLI's error contract, one check for every test of it: exit status 2 and one stderr
line, ``sma-fmu: error: ...``, containing the given parts."""
from sma_fmu.cli import main

__all__ = ["fails"]


def fails(capsys, argv, *parts):
    """Run ``sma-fmu argv``; assert the contract; return the error line."""
    try:
        status = main(argv)
    except SystemExit as stop:  # argparse errors
        status = stop.code
    err = capsys.readouterr().err
    assert status == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("sma-fmu: error: "), err
    for part in parts:
        assert part in lines[0], lines[0]
    return lines[0]
