"""The scenarios in every host, against the library loop: ``sma-fmu bench --only hosts``.

Not a speed benchmark: it prints the per-host table of docs/systems.md. Per scenario
(default: the six paper scenarios and the two PWM set-point ones) and run: the RMSE of
R - R_ref (t >= 2 s) [ohm] and the largest deviation, over every time-series column, from
the library run of the same coupling. The runs: the library path (Gauss-Seidel and
Jacobi); the SSP in libcosim, Ecos, fmpy's ``simulate_ssp`` (its recorded columns) and,
when SMA_FMU_OMSIMULATOR names its executable (or ``--omsimulator`` does), OMSimulator;
the container FMU in fmpy and libcosim. It builds the FMUs into a temporary folder. A 30 s
scenario takes 1-30 s per host.

    sma-fmu bench --only hosts [--scenario NAME ...] [--stop-time S] [--omsimulator EXE] [--out DIR]
"""
import dataclasses
import os
import tempfile
from pathlib import Path

from sma_fmu.cosim.scenario import PAPER_SET, load_scenario, resolve_scenarios
from sma_fmu.files.json_output import json_text
from sma_fmu.fmi.packaging.build import build_fmus
from sma_fmu.systems.comparison import FMPY_SSP, compare_hosts, host_table
from sma_fmu.systems.omsimulator import ENVIRONMENT, omsimulator_executable

__all__ = ["SCENARIOS", "run_host_table"]

SCENARIOS = (*PAPER_SET, "setpoints-pwm-pi+ff-adaptive", "setpoints-pwm-continuous-pi+ff-adaptive")


def run_host_table(out_dir, scenarios=None, stop_time_s=None, omsimulator=None, say=print):
    """Run every scenario in every host, print the table, write ``out_dir``/hosts.json; returns the rows.

    ``scenarios``: names or files (default :data:`SCENARIOS`); ``stop_time_s`` [s] shortens
    every run; ``omsimulator``: OMSimulator's executable (default: $SMA_FMU_OMSIMULATOR, else
    OMSimulator is left out).
    """
    if omsimulator:
        os.environ[ENVIRONMENT] = str(omsimulator)
    hosts = ["libcosim", "ecos"] + (["omsimulator"] if omsimulator_executable() else [])
    hosts += [FMPY_SSP, "fmpy", "libcosim-container"]
    rows = []
    with tempfile.TemporaryDirectory(prefix="sma_fmu_hosts_") as folder:
        build_fmus(folder)
        for path in resolve_scenarios(list(scenarios or SCENARIOS)):
            scenario = load_scenario(path)
            if stop_time_s:
                scenario = dataclasses.replace(scenario, stop_time_s=stop_time_s)
            rows += compare_hosts(scenario, folder, hosts=hosts)
            say(f"{scenario.name}: " + ", ".join(f"{row['run']} {row['wall_time_s']:.1f} s"
                                                 for row in rows if row["scenario"] == scenario.name))
    say("")
    say(host_table(rows))
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    (out / "hosts.json").write_text(json_text(rows), encoding="utf-8")
    say(f"written: {out / 'hosts.json'}")
    return rows
