"""By hand: 50 Ctrl-Cs at random moments, 10 per command, across ``run paper`` (the fmpy
master and the C master), ``build``, ``build --native`` and ``fit isobaric`` (the shipped
example). Each must end with one line ``sma-fmu: interrupted`` (``... after writing OUT in
full`` when the results were in place, OUT then whole), exit status 130, no traceback,
and leave no new file or folder (tests/support/interrupting.py). Half of them go to the whole
process group (a terminal's Ctrl-C), half to sma-fmu alone (``kill -INT``). Prints one line per
interrupt and a count; exit status 1 when one broke the contract.

    python tests/cli/interrupts_check.py [--seed N] [--per-command 10]

Takes about 15 minutes on the 2-core VM (the inputs are built first, the C family's compiler
cache fills on the first native build).
"""
import argparse
import random
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[1] / "support"))

from interrupting import interrupt_in_time  # noqa: E402
from test_interrupts import COMMANDS  # noqa: E402

from sma_fmu.files.package_data import shipped_file  # noqa: E402
from sma_fmu.fmi.packaging.build import build_fmus  # noqa: E402

# the latest moment of an interrupt per command [s], by hand: the commands' whole length here
LATEST_S = {"run paper (fmpy master)": 12.0, "run paper (C master)": 4.0, "build": 20.0,
            "build --native": 90.0, "fit isobaric": 10.0}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=48)
    parser.add_argument("--per-command", type=int, default=10)
    options = parser.parse_args()
    rng = random.Random(options.seed)
    with tempfile.TemporaryDirectory(prefix="sma-fmu-interrupts-") as folder:
        work = Path(folder)
        print("building the inputs ...", flush=True)
        build_fmus(work / "fmus")
        build_fmus(work / "native", native=True)
        (work / "isobaric.csv").write_bytes(shipped_file("examples", "isobaric.csv").read_bytes())
        plan = [(name, rng.uniform(0.3, LATEST_S[name]), index % 2 == 0)
                for name in COMMANDS for index in range(options.per_command)]
        rng.shuffle(plan)
        kept, broke, finished = 0, 0, 0
        for name, after_s, group in plan:
            result = interrupt_in_time(COMMANDS[name][0], work, after_s, timeout_s=300,
                                       group=group)   # ended first: again, earlier
            after_s, problems = result.after_s, result.problems()
            how = "group" if group else "process"
            if problems is None:
                finished += 1
                print(f"finished before  {name} at {after_s:6.2f} s ({how})", flush=True)
            elif problems:
                broke += 1
                print(f"BROKE            {name} at {after_s:6.2f} s ({how}): {problems}", flush=True)
            else:
                kept += 1
                print(f"ok               {name} at {after_s:6.2f} s ({how})", flush=True)
    print(f"{kept + broke + finished} interrupts: {kept} ok, {broke} broke the contract, "
          f"{finished} came after the command had finished (each retried earlier, down to 0.3 s)")
    return 1 if broke else 0


if __name__ == "__main__":
    sys.exit(main())
