"""The paper scenarios in every host, against the library loop: ``python benchmarks/hosts.py``.

Not a speed benchmark: it prints the table of docs/systems.md, the RMSE of R - R_ref
(t >= 2 s) per scenario for the library path (Gauss-Seidel and Jacobi) and for each host
(libcosim and Ecos run the SSP, fmpy and libcosim the container FMU), and the largest
deviation of a host run from the library run of its coupling. It builds the FMUs into a
temporary folder. A 30 s scenario takes 10-40 s per host (about 10 minutes in all).

    python benchmarks/hosts.py [SCENARIO...] [--stop-time S] [--json FILE]
"""
import argparse
import dataclasses
import sys
import tempfile

from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios
from sma_fmu.fmi.build import build_fmus
from sma_fmu.json_output import json_text
from sma_fmu.systems.comparison import compare_hosts, rmse_table


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="*", default=["paper"], metavar="SCENARIO")
    parser.add_argument("--stop-time", type=float, metavar="S", help="shorten every scenario to S s")
    parser.add_argument("--json", metavar="FILE", help="also write the rows as JSON")
    args = parser.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory(prefix="sma_fmu_hosts_") as folder:
        build_fmus(folder)
        for path in resolve_scenarios(args.scenarios):
            scenario = load_scenario(path)
            if args.stop_time:
                scenario = dataclasses.replace(scenario, stop_time_s=args.stop_time)
            rows += compare_hosts(scenario, folder)
            print(f"{scenario.name}: " + ", ".join(
                f"{row['run']} {row['rmse_ohm']:.3f} ({row['wall_time_s']:.1f} s)"
                for row in rows if row["scenario"] == scenario.name), flush=True)
    print(rmse_table(rows))
    if args.json:
        with open(args.json, "w", encoding="utf-8") as stream:
            stream.write(json_text(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
