"""A scenario's closed loop in the plain C loop host (``sma_fmu/fmi/hosts/loop_host.c``).

The loop host is what an embedded or HIL master is: one C process that loads the FMUs'
binaries itself (no libpython, no FMI library) and steps them one after the other in
:data:`~sma_fmu.fmi.loop.wiring.STEP_ORDER` (Gauss-Seidel), each with the outputs just computed by the
ones before it, so it computes what the library's Gauss-Seidel loop computes. With the
native (C) family nothing in that process is Python: the HIL case of the benchmark.

The same source is cross-built with mingw-w64 (``windows=True``) and run under wine64, with
the FMUs' win64 binaries: the model's run on Windows, compared with linux64's.
"""
import os
import shutil
import subprocess
import zipfile
from pathlib import Path

import numpy as np

from sma_fmu.files.archives import require_safe_archive
from sma_fmu.fmi.hosts import CHostError, compile_host

__all__ = ["loop_host_lines", "run_loop_host", "wine_executable", "wine_path"]

_KINDS = {"Real": "real", "Integer": "integer", "Enumeration": "integer", "Boolean": "boolean",
          "String": "string"}


def wine_executable():
    """wine64 on the PATH, else where Debian's wine64 package puts it."""
    return shutil.which("wine64") or "/usr/lib/wine/wine64"


def wine_path(path):
    """``path`` as a Windows program under wine sees it (drive Z: is /)."""
    return "Z:" + str(Path(path).resolve()).replace("/", "\\")


def _value(kind, value):
    if kind == "string":
        return value.encode("utf-8").hex() or "_"
    if kind == "real":
        return repr(float(value))
    return str(int(value))


def loop_host_lines(system, folders, steps, timing=False, columns=None):
    """The loop host's input for ``system`` (a :class:`~sma_fmu.fmi.loop.system.LoopSystem`)
    whose FMUs are unpacked in ``folders`` ({component: folder text}); a list of lines. The
    recorded columns are ``columns`` (default: the system's outputs), in that order."""
    lines = []
    for component in system.components:
        lines.append(f"fmu {component.name} {folders[component.name]}")
        for name, value in component.parameters.items():
            variable = component.variables[name]
            kind = _KINDS[variable.type]
            lines.append(f"{kind} {component.name} {variable.valueReference} {_value(kind, value)}")
    for c in system.connections:
        source, target = system.component(c.source), system.component(c.target)
        lines.append(f"connect {c.source} {source.variables[c.output].valueReference} "
                     f"{c.target} {target.variables[c.input].valueReference}")
    lines.append("order " + " ".join(component.name for component in system.in_step_order()))
    outputs = system.outputs
    for name, variable in (outputs[column] for column in (columns or outputs)):
        v = system.component(name).variables[variable]
        lines.append(f"record {'boolean' if v.type == 'Boolean' else 'real'} {name} {v.valueReference}")
    step = repr(float(system.scenario.step_s))
    lines.append(f"run {step} {steps}" + (" timing" if timing else ""))
    return lines


def run_loop_host(system, steps, work, windows=None, timing=False, timeout=3600):
    """Run ``system`` for ``steps`` steps in the loop host; returns (samples, logs, timing).

    ``work``: a folder for the host and the unpacked FMUs. ``windows``: None for the linux64
    build, else the environment of a wine64 prefix (the win64 build runs under wine with the
    FMUs' win64 binaries). samples: {column: array of the n + 1 samples} (only the last with
    ``timing``); logs: [(status, component, text)] the FMUs logged; timing: None, or
    {"p50_us", "p99_us", "p99_9_us", "max_us", "total_s"} of the steps. Raises
    :class:`~sma_fmu.fmi.hosts.CHostError` naming the failed call when the host fails.
    """
    work = Path(work)
    folders = {}
    for component in system.components:
        folder = work / "fmus" / component.name
        if not folder.is_dir():
            require_safe_archive(component.fmu)
            with zipfile.ZipFile(component.fmu) as archive:
                archive.extractall(folder)
        folders[component.name] = wine_path(folder) if windows is not None else str(folder)
    executable = compile_host("loop_host", work / "hosts", windows=windows is not None)
    command = [str(executable)] if windows is None else [wine_executable(), str(executable)]
    environment = dict(os.environ if windows is None else windows)
    environment.pop("LD_PRELOAD", None)
    text = "\n".join(loop_host_lines(system, folders, steps, timing)) + "\n"
    result = subprocess.run(command, input=text, capture_output=True, text=True,
                            env=environment, timeout=timeout)
    if result.returncode != 0:
        message = (result.stderr.strip() or result.stdout.strip()).splitlines()
        raise CHostError(f"loop host{' (win64, wine)' if windows is not None else ''}: exit "
                         f"status {result.returncode}: {message[-1] if message else 'no message'}")
    rows, logs, measured = [], [], None
    for line in result.stdout.splitlines():
        words = line.split()
        if words[:1] == ["row"]:
            rows.append([float(w) for w in words[1:]])
        elif words[:1] == ["log"]:
            body = "" if words[4] == "_" else bytes.fromhex(words[4]).decode("utf-8", "replace")
            logs.append((int(words[1]), words[2], body))
        elif words[:1] == ["timing"]:
            measured = dict(zip(("p50_us", "p99_us", "p99_9_us", "max_us", "total_s"),
                                map(float, words[1:])))
    names = list(system.outputs)
    table = np.array(rows, dtype=float).reshape(len(rows), len(names))
    samples = {name: (table[:, i] != 0.0 if name == "saturated" else table[:, i])
               for i, name in enumerate(names)}
    return samples, logs, measured

