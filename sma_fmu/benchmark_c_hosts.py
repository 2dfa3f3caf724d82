"""What a SmaActuator step costs in C hosts, before and after the native front.

Each host runs 30,000 steps of 1 ms (P_in = 2.6 W, load = 0.05 kg) and times every step:
- the plain ``dlopen`` C host (``sma_fmu/fmi/hosts/fmi_host.c``): set P_in + doStep + get T;
- libcosim (sma-fmu's C host ``hosts/cosim_host.c --timing``, if libcosimpy is installed):
  one ``cosim_execution_step`` (libcosim sets, steps and reads the FMU's variables itself).
"Before" is pythonfmu's own binary with libpython in LD_PRELOAD (what the FMUs were);
"after" is the front, which also keeps one Python thread state per host thread; the front
without that keeper (SMA_FMU_NO_TSTATE=1) shows what the keeper alone is worth.
"""
import importlib.util
import shutil
import statistics
import subprocess
from pathlib import Path

from sma_fmu.fmi.front import libpython_path, remove_front
from sma_fmu.fmi.hosts import compile_host
from sma_fmu.systems.c_host import host_environment

__all__ = ["C_HOST_STEPS", "c_host_step_costs"]

C_HOST_STEPS = 30_000
_STEP = 1e-3


def _references(fmu):
    from sma_fmu.fmi.build import read_description
    return {v.name: v.valueReference for v in read_description(fmu).modelVariables}


def _environment(extra):
    """The C host's environment without the front's switches, plus ``extra``."""
    return {**host_environment(drop=("SMA_FMU_LIBPYTHON", "SMA_FMU_NO_TSTATE")), **extra}


def _plain_host(exe, folder, refs, env):
    """(mean, p50, p99, p99.9) [us] of set + doStep + get in fmi_host."""
    commands = "\n".join([
        f"instantiate 0 {b'bench'.hex()} ok ok 0", "setup 0 0 -", "enter 0",
        f"setreal 0 1 {refs['load']} 0.05", "exit 0",
        f"bench 0 {C_HOST_STEPS} {_STEP} {refs['P_in']} 2.6 {refs['T']} 0", "end", ""])
    result = subprocess.run([str(exe), str(folder)], input=commands, capture_output=True, text=True,
                            env=_environment(env), timeout=600, check=True)
    words = [line.split() for line in result.stdout.splitlines() if line.startswith("= ")][-1]
    if words[1] != "0":
        raise RuntimeError(f"the C host's bench failed: {result.stdout[-500:]}")
    p50, p99, p999, total = map(float, words[3:7])
    return total / C_HOST_STEPS * 1e6, p50, p99, p999


def _libcosim(exe, fmu, env):
    """(mean, p50, p99, p99.9) [us] of one libcosim step."""
    result = subprocess.run(
        [str(exe), "--timing", "fmu", str(fmu), repr(_STEP), str(C_HOST_STEPS), "P_in=2.6",
         "load=0.05"], capture_output=True, text=True, env=_environment(env), timeout=600)
    timing = [line.split() for line in result.stdout.splitlines() if line.startswith("timing ")]
    if result.returncode != 0 or not timing:
        raise RuntimeError(f"libcosim run failed: {(result.stdout + result.stderr)[-500:]}")
    p50, p99, p999, total = map(float, timing[-1][1:])
    return total / (C_HOST_STEPS - 1) * 1e6, p50, p99, p999


def c_host_step_costs(fmu, runs, folder):
    """{host and configuration: {mean_us, p50_us, p99_us, p99_9_us}} (medians of ``runs``)."""
    folder = Path(folder)
    refs = _references(fmu)
    before = remove_front(fmu, folder / "SmaActuator-pythonfmu.fmu")
    unpacked = {}
    for name, path in (("front", fmu), ("pythonfmu", before)):
        unpacked[name] = folder / f"unpacked-{name}"
        shutil.unpack_archive(str(path), str(unpacked[name]), "zip")
    preload = {"LD_PRELOAD": libpython_path()[0]}
    host = compile_host("fmi_host", folder)
    cases = {
        "plain C host, pythonfmu + LD_PRELOAD (before)": lambda: _plain_host(host, unpacked["pythonfmu"], refs, preload),
        "plain C host, front without thread-state keeper": lambda: _plain_host(
            host, unpacked["front"], refs, {"SMA_FMU_NO_TSTATE": "1"}),
        "plain C host, front (after)": lambda: _plain_host(host, unpacked["front"], refs, {}),
    }
    if importlib.util.find_spec("libcosimpy") is not None:
        cosim = compile_host("cosim_host", folder)
        cases["libcosim step, pythonfmu + LD_PRELOAD (before)"] = lambda: _libcosim(cosim, before, preload)
        cases["libcosim step, front (after)"] = lambda: _libcosim(cosim, fmu, {})
    results = {}
    for name, measure in cases.items():
        samples = list(zip(*(measure() for _ in range(runs))))
        results[name] = {key: round(statistics.median(values), 3) for key, values in
                         zip(("mean_us", "p50_us", "p99_us", "p99_9_us"), samples)}
    return results
