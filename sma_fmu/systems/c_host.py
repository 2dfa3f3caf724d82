"""sma-fmu's C host: a small C program on libcosim's C API, built on first use, run as a process.

It loads an FMU (or an SSP package) the way a C/C++ tool does: through libcosim and the FMI
Library, in a process that is not Python. The program (``sma_fmu/fmi/hosts/cosim_host.c``)
is built by :func:`sma_fmu.fmi.hosts.compile_host` with the system C compiler (``$CC``,
else ``cc``) against the libcosimc of the libcosimpy wheel, once per source and library,
into a cache folder.

The FMUs carry a C front library that loads libpython itself (docs/fmus.md), so the
host process needs nothing preloaded: :func:`host_environment` removes LD_PRELOAD, and the
runs show what any C tool sees.
"""
import os
import re
import subprocess

from sma_fmu.files.archives import require_safe_archive
from sma_fmu.fmi.hosts import CHostError, compile_host

__all__ = ["CHostError", "host_environment", "run_c_host"]

_OUTPUT_LINE = re.compile(r"([^=\s]+)=(\S+)")


def host_environment(environment=None, drop=()):
    """The environment for a C host process: ``environment`` (default os.environ) without
    LD_PRELOAD (the FMUs load libpython themselves) and without the keys in ``drop``.

    ``sma-fmu check`` drops nothing more, so a user's ``SMA_FMU_LIBPYTHON`` is honoured;
    the benchmark also drops the front's own switches to measure it as shipped.
    """
    environment = dict(os.environ if environment is None else environment)
    for key in ("LD_PRELOAD", *drop):
        environment.pop(key, None)
    return environment


def run_c_host(kind, path, step_size, steps, timeout=600):
    """Run ``path`` ("fmu" or "ssp" ``kind``) in the C host; returns {"slave.variable": value}.

    ``step_size`` [s], ``steps``: the fixed steps to take. Raises :class:`CHostError` with
    the host's message when it fails.
    """
    require_safe_archive(path)  # libcosim unpacks it: never one that leaves its folder
    executable = compile_host("cosim_host")
    result = subprocess.run([str(executable), kind, str(path), repr(float(step_size)), str(steps)],
                            capture_output=True, text=True, env=host_environment(),
                            timeout=timeout)
    if result.returncode != 0:
        message = (result.stderr.strip() or result.stdout.strip()).splitlines()
        raise CHostError(f"C host (libcosim) on {path}: exit status {result.returncode}: "
                         f"{message[-1] if message else 'no message'}")
    values = {}
    for line in result.stdout.splitlines():  # libcosim also logs to stdout
        match = _OUTPUT_LINE.fullmatch(line.strip())
        if match:
            values[match.group(1)] = float(match.group(2))
    return values
