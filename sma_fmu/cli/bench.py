"""Benchmark command: how fast the FMUs, the co-simulation and the fits run."""
from pathlib import Path

from .arguments import bounded_integer

MAX_RUNS = 1000   # choice: repetitions per measurement; more only takes longer

__all__ = ["register"]


def _bench(args):
    from sma_fmu.bench.benchmark import main as bench_main
    return bench_main(args.out, args.runs, args.only, args.quick)


def register(commands):
    """Add ``bench`` to the ``commands`` subparsers."""
    bench = commands.add_parser("bench", help="measure speed; print a table and write JSON")
    bench.add_argument("--out", type=Path, default=Path("results/benchmark"), metavar="DIR",
                       help="output folder")
    bench.add_argument("--runs", type=bounded_integer(1, MAX_RUNS), default=5,
                       help=f"repetitions per measurement, 1-{MAX_RUNS}")
    bench.add_argument("--only", choices=("batch",),
                       help="only this section (batch: the batch engine's throughput table)")
    bench.add_argument("--quick", action="store_true",
                       help="with --only batch: N up to 1,000 only (a quick look)")
    bench.set_defaults(handler=_bench)
