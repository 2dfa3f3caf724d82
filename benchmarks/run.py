"""Run the benchmarks: ``python benchmarks/run.py [--out DIR] [--runs N]`` (same as ``sma-fmu bench``)."""
import sys

from sma_fmu.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", *sys.argv[1:]]))
