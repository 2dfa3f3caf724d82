"""Benchmark command: how fast the FMUs, the co-simulation and the fits run."""
from pathlib import Path

from .arguments import bounded_integer, positive_number

MAX_RUNS = 1000   # choice: repetitions per measurement; more only takes longer

__all__ = ["register"]


def _bench(args):
    if args.only == "hosts":
        from sma_fmu.bench.host_table import run_host_table
        run_host_table(args.out, args.scenario, args.stop_time, args.omsimulator)
        return 0
    if args.only == "c-master":
        from sma_fmu.bench.c_master import c_master_lines, run_c_master_bench
        say = lambda text: print(text, flush=True)  # noqa: E731
        results = run_c_master_bench(args.out, args.runs, args.fmus, progress=say)
        print("\n".join(c_master_lines(results["c_master"], results["one_hour"],
                                        results["commands"], results["sweep"])))
        print(f"written: {args.out / 'benchmark.json'}")
        return 0
    if args.only == "inverse":
        from sma_fmu.bench.inverse import inverse_lines, run_inverse_bench
        say = lambda text: print(text, flush=True)  # noqa: E731
        results = run_inverse_bench(args.out, args.runs, args.model, args.stop_time, say)
        print("\n".join(inverse_lines(results)))
        print(f"written: {args.out / 'benchmark.json'}")
        return 0
    if args.only == "hardware":
        from sma_fmu.bench.hardware import hardware_lines, run_hardware_bench
        say = lambda text: print(text, flush=True)  # noqa: E731
        results = run_hardware_bench(args.out, args.runs, args.fmus, say)
        print("\n".join(hardware_lines(results)))
        print(f"written: {args.out / 'benchmark.json'}")
        return 0
    if args.only == "stroke":
        from sma_fmu.bench.stroke import run_stroke_bench, stroke_lines
        say = lambda text: print(text, flush=True)  # noqa: E731
        results = run_stroke_bench(args.out, args.runs, say, args.fmus)
        print("\n".join(stroke_lines(results)))
        print(f"written: {args.out / 'benchmark.json'}")
        return 0
    if args.only == "pwm":
        from sma_fmu.bench.pwm_table import pwm_table_rows
        pwm_table_rows()
        return 0
    from sma_fmu.bench.benchmark import main as bench_main
    return bench_main(args.out, args.runs, args.only, args.quick)


def register(commands):
    """Add ``bench`` to the ``commands`` subparsers."""
    bench = commands.add_parser("bench", help="measure speed; print a table and write JSON")
    bench.add_argument("--out", type=Path, default=Path("results/benchmark"), metavar="DIR",
                       help="output folder")
    bench.add_argument("--runs", type=bounded_integer(1, MAX_RUNS), default=5,
                       help=f"repetitions per measurement, 1-{MAX_RUNS}")
    bench.add_argument("--only", choices=("batch", "hosts", "pwm", "c-master", "inverse",
                                          "hardware", "stroke"),
                       help="only this section (batch: the batch engine's throughput table; "
                            "hosts: every scenario in every host against the library loop, "
                            "docs/systems.md's table; pwm: the PWM table of docs/model.md; "
                            "c-master: the C master against the library: the loop per "
                            "scenario, whole run commands, the run table's wall s, a sweep per "
                            "worker, the peak memory of a one-hour run; inverse: one inversion "
                            "of a two-stage wire in Python and C, and heavy-pi+ff-adaptive "
                            "through its FMUs against the reference wire's; hardware: the "
                            "sensor's and the drive limit's cost per step in Python and C, and "
                            "the C master against the library on the bench scenarios; stroke: "
                            "the stroke map's cost per step and the stroke scenarios' runs)")
    bench.add_argument("--fmus", type=Path, metavar="DIR",
                       help="with --only c-master or hardware: the native FMUs (sma-fmu build "
                            "--native; default: built into the output folder); with --only "
                            "stroke: the C master's runs too (default: none)")
    bench.add_argument("--model", type=Path, metavar="FILE",
                       help="with --only inverse: the two-stage wire's parameter file (e.g. "
                            "a fit's identified.toml; default: the reference wire with a "
                            "broad second stage)")
    bench.add_argument("--scenario", action="append", metavar="NAME",
                       help="with --only hosts: a scenario (repeatable; default: the paper's six "
                            "and the two PWM set-point ones)")
    bench.add_argument("--stop-time", type=positive_number, metavar="S",
                       help="with --only hosts or inverse: shorten every scenario to S s")
    bench.add_argument("--omsimulator", metavar="EXE",
                       help="with --only hosts: OMSimulator's executable (default: "
                            "$SMA_FMU_OMSIMULATOR, else OMSimulator is left out)")
    bench.add_argument("--quick", action="store_true",
                       help="with --only batch: N up to 1,000 only (a quick look)")
    bench.set_defaults(handler=_bench)
