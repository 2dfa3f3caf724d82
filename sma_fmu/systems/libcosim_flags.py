"""Booleans recorded in libcosim without fetching every variable of every slave.

libcosim's time-series observer takes Reals and Integers only. Its last-value observer
takes Booleans but exposes every variable of every slave for getting, so libcosim fetches
all of them after each step (on the stroke profile that includes the signals FMU's
0.79 MB ``reference`` String: 0.5 ms a step with the pythonfmu FMUs). Its file observer,
given a log configuration, exposes only the variables the configuration names, Booleans
included, and writes them to one CSV file per slave (``<slave>.csv``:
``Time,StepCount,<variables>``, a row per step from step 0, after initialization, on; a
Boolean as 0 or 1).

libcosimpy (0.0.6, and 0.0.7) leaves that observer's constructor commented out, so
:func:`file_observer` calls libcosimc's ``cosim_file_observer_create_from_cfg`` and wraps
it as libcosimpy's own observer. libcosim writes the rows through a buffered stream that
it closes only once the observer and the execution are both gone: :func:`read_flags` reads
the files after that.
"""
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

__all__ = ["file_observer", "read_flags"]

CONFIG_NAME = "log-config.xml"


def file_observer(folder, flags):
    """libcosim's file observer logging only ``flags`` ({column: (slave, variable)}) into ``folder``.

    Writes the log configuration into ``folder``; returns a libcosimpy ``CosimObserver``.
    """
    from ctypes import POINTER, c_char_p

    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy._internal import libcosimc, wrap_function

    config = Path(folder) / CONFIG_NAME
    config.write_text(_config_xml(flags), encoding="utf-8")
    create = wrap_function(lib=libcosimc(), funcname="cosim_file_observer_create_from_cfg",
                           argtypes=[c_char_p, c_char_p], restype=POINTER(CosimObserver))
    pointer = create(str(folder).encode(), str(config).encode())
    return CosimObserver(CosimObserver._CosimObserver__create_key, pointer)


def _config_xml(flags):
    """The log configuration: plain file names (no time stamp), the named variables only."""
    variables = {}
    for slave, variable in flags.values():
        variables.setdefault(slave, []).append(variable)
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             '<configuration timestampedFilenames="false"/>', "<simulators>"]
    for slave, names in variables.items():
        lines.append(f"  <simulator name={quoteattr(slave)} decimationFactor=\"1\">")
        lines += [f"    <variable name={quoteattr(name)}/>" for name in names]
        lines.append("  </simulator>")
    lines.append("</simulators>")
    return "\n".join(lines) + "\n"


def read_flags(folder, flags, steps, what):
    """{column: n + 1 Booleans, at steps 0 ... n} from the closed files of :func:`file_observer`.

    A file missing, or with other columns or steps than expected, is a ``ValueError``
    naming ``what`` (the system run) and the file.
    """
    tables = {}
    samples = {}
    for column, (slave, variable) in flags.items():
        path = Path(folder) / f"{slave}.csv"
        if path not in tables:
            tables[path] = _read_log(path, steps, what)
        header, rows = tables[path]
        if variable not in header:
            raise ValueError(f"libcosim: {what}: {path.name} has no column {variable}")
        values = rows[:, header.index(variable)]
        if not np.isin(values, (0, 1)).all():
            raise ValueError(f"libcosim: {what}: {path.name}: {variable} is not 0 or 1")
        samples[column] = values == 1
    return samples


def _read_log(path, steps, what):
    """(column names, array of rows) of one of libcosim's CSV logs, steps 0 ... ``steps``."""
    if not path.is_file():
        raise ValueError(f"libcosim: {what}: its file observer wrote no {path.name}")
    with path.open(encoding="utf-8") as file:
        header = file.readline().strip().split(",")
        rows = np.loadtxt(file, delimiter=",", ndmin=2)
    if rows.shape[0] != steps + 1 or header[:2] != ["Time", "StepCount"] \
            or not np.array_equal(rows[:, 1], np.arange(steps + 1)):
        raise ValueError(f"libcosim: {what}: {path.name} does not hold steps 0 ... {steps}")
    return header, rows
