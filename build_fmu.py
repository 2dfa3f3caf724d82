"""Build both FMUs (SmaActuator, SmaFeedforward): ``python build_fmu.py [--out DIR] [--model FILE]``.

The same as ``sma-fmu build``; the work is done by :mod:`sma_fmu.fmi.build`.
"""
import sys

from sma_fmu.cli import main

if __name__ == "__main__":
    sys.exit(main(["build", *sys.argv[1:]]))
