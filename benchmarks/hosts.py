"""The scenarios in every host, against the library loop: ``python benchmarks/hosts.py``.

Not a speed benchmark: it prints the per-host table of docs/systems.md. Per scenario
(default: the six paper scenarios and the two PWM set-point ones) and run: the RMSE of
R - R_ref (t >= 2 s) [ohm] and the largest deviation, over every time-series column, from
the library run of the same coupling. The runs: the library path (Gauss-Seidel and
Jacobi); the SSP in libcosim, Ecos, fmpy's ``simulate_ssp`` (its recorded columns only;
"–" where it cannot run) and, when SMA_FMU_OMSIMULATOR names its executable (or
``--omsimulator`` does), OMSimulator; the container FMU in fmpy and libcosim. It builds
the FMUs into a temporary folder. A 30 s scenario takes 1-30 s per host.

    python benchmarks/hosts.py [SCENARIO...] [--stop-time S] [--omsimulator EXE] [--json FILE]
"""
import argparse
import dataclasses
import os
import sys
import tempfile

from sma_fmu.cosim.scenario import PAPER_SET, load_scenario, resolve_scenarios
from sma_fmu.fmi.build import build_fmus
from sma_fmu.files.json_output import json_text
from sma_fmu.systems.comparison import FMPY_SSP, compare_hosts, host_table
from sma_fmu.systems.omsimulator import ENVIRONMENT, omsimulator_executable

SCENARIOS = (*PAPER_SET, "setpoints-pwm-pi+ff-adaptive", "setpoints-pwm-continuous-pi+ff-adaptive")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="*", default=list(SCENARIOS), metavar="SCENARIO")
    parser.add_argument("--stop-time", type=float, metavar="S", help="shorten every scenario to S s")
    parser.add_argument("--omsimulator", metavar="EXE",
                        help=f"OMSimulator's executable (default: ${ENVIRONMENT}, else not run)")
    parser.add_argument("--json", metavar="FILE", help="also write the rows as JSON")
    args = parser.parse_args(argv)
    if args.omsimulator:
        os.environ[ENVIRONMENT] = args.omsimulator
    hosts = ["libcosim", "ecos"] + (["omsimulator"] if omsimulator_executable() else [])
    hosts += [FMPY_SSP, "fmpy", "libcosim-container"]
    rows = []
    with tempfile.TemporaryDirectory(prefix="sma_fmu_hosts_") as folder:
        build_fmus(folder)
        for path in resolve_scenarios(args.scenarios):
            scenario = load_scenario(path)
            if args.stop_time:
                scenario = dataclasses.replace(scenario, stop_time_s=args.stop_time)
            rows += compare_hosts(scenario, folder, hosts=hosts)
            print(f"{scenario.name}: " + ", ".join(
                f"{row['run']} {row['wall_time_s']:.1f} s"
                for row in rows if row["scenario"] == scenario.name), flush=True)
    print()
    print(host_table(rows))
    if args.json:
        with open(args.json, "w", encoding="utf-8") as stream:
            stream.write(json_text(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
