"""A scenario run through its SSP package or its container FMU in a host, as a loop result.

These are the ``ssp`` and ``container`` paths of ``sma-fmu run``. Both build the artifact
from the FMUs in ``fmu_dir`` into a temporary folder and run it in libcosim: the SSP as
the system tools run it (Jacobi coupling), the container as one FMU (sequential inside,
so Gauss-Seidel). **choice**: libcosim rather than Ecos, because its wheel needs nothing
else (Ecos needs libtbb loaded first) and it is the Open Simulation Platform's reference.
"""
import tempfile
import time
from pathlib import Path

from sma_fmu.cosim.loop import LoopResult
from sma_fmu.systems import hosts
from sma_fmu.systems.closed_loop import closed_loop
from sma_fmu.fmi.loop.wiring import loop_outputs
from sma_fmu.systems.container import build_container
from sma_fmu.systems.omsimulator import run_ssp_omsimulator
from sma_fmu.systems.ssp import write_ssp

__all__ = ["HOSTS", "DEFAULT_HOSTS", "write_artifact", "run_host", "run_ssp", "run_container"]

# host -> (artifact, coupling the host applies,
#          function(artifact path, scenario, the loop's outputs) -> samples)
HOSTS = {
    "libcosim": ("ssp", "jacobi", lambda path, s, out: hosts.run_ssp_libcosim(path, s.steps, out)),
    "ecos": ("ssp", "jacobi", lambda path, s, out: hosts.run_ssp_ecos(path, s.step_s, s.steps, out)),
    "fmpy": ("container", "gauss-seidel",
             lambda path, s, out: hosts.run_container_fmpy(path, s.step_s, s.steps, out)),
    "libcosim-container": ("container", "gauss-seidel", lambda path, s, out:
                           hosts.run_container_libcosim(path, s.step_s, s.steps, out)),
    # not on any package registry: runs when SMA_FMU_OMSIMULATOR names its executable
    "omsimulator": ("ssp", "jacobi",
                    lambda path, s, out: run_ssp_omsimulator(path, s.step_s, s.steps, out)[0]),
}
# the hosts the package's dependencies bring (pip installs them): what the tests run
DEFAULT_HOSTS = ("libcosim", "ecos", "fmpy", "libcosim-container")
_BUILDERS = {"ssp": write_ssp, "container": build_container}


def write_artifact(kind, system, folder):
    """Write the ``kind`` ("ssp" or "container") of ``system`` into ``folder``; returns its path."""
    path = Path(folder) / f"{system.scenario.name}.{'ssp' if kind == 'ssp' else 'fmu'}"
    _BUILDERS[kind](system, path)
    return path


def run_host(host, scenario, fmu_dir, artifact=None):
    """Run ``scenario`` in ``host`` (a key of :data:`HOSTS`); returns a :class:`LoopResult`.

    ``artifact``: a path of an already written .ssp / container FMU of this scenario;
    by default one is built from the FMUs in ``fmu_dir`` into a temporary folder.
    """
    if host not in HOSTS:
        raise ValueError(f"host must be one of {', '.join(HOSTS)}, got {host!r}")
    kind, _, run = HOSTS[host]
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="sma_fmu_run_") as folder:
        if artifact is None:
            artifact = write_artifact(kind, closed_loop(scenario, fmu_dir), folder)
        samples = run(artifact, scenario, loop_outputs(scenario.controller.feedforward))
        data = hosts.loop_series(scenario, samples, scenario.steps)
    return LoopResult(scenario, data, f"{kind} ({host})", time.perf_counter() - start)


def run_ssp(scenario, fmu_dir):
    """``sma-fmu run --path ssp``: the scenario's SSP package in libcosim."""
    return run_host("libcosim", scenario, fmu_dir)


def run_container(scenario, fmu_dir):
    """``sma-fmu run --path container``: the scenario's container FMU in libcosim."""
    return run_host("libcosim-container", scenario, fmu_dir)
