"""One FMU's declaration: its folder's ``fmu.toml``, read and checked (:func:`read_declaration`).

Keys (only ``slave`` is required)::

    slave = "sma_pwm_driver.py"   # the pythonfmu slave script in the folder
    loop = "driver"               # its component name in the closed loop
    events = true                 # FMI 3.0: events of its own (its adapter's next_event)
    default_signals = "..."       # a shipped scenario whose signals are its defaults
    [stimuli]                     # the default experiment's inputs: [[t s, value], ...]
    P_demand = [[0.0, 0.0], [8.0, 12.0], [10.0, 12.0]]

The folder's other files have fixed names: the C adapter ``<Model>.c`` (the FMU's model
identifier: the C family's ``sources/`` are flat) and the documentation page ``page.html``.
"""
import math
from dataclasses import dataclass, field
from pathlib import Path

from sma_fmu.files.toml_files import read_toml

__all__ = ["FOLDER", "DECLARATION_FILE", "PAGE_FILE", "Declaration", "read_declaration"]

FOLDER = Path(__file__).parent     # holds one folder per FMU
DECLARATION_FILE = "fmu.toml"
PAGE_FILE = "page.html"
_TYPES = {"slave": str, "loop": str, "events": bool, "default_signals": str, "stimuli": dict}


@dataclass(frozen=True)
class Declaration:
    """What one FMU declares: ``name`` (its folder, model name and model identifier), its
    pythonfmu ``slave`` script's file name, its ``loop`` component name (None: not in the
    loop), ``events`` (FMI 3.0: it may end a step early at an event of its own), the
    ``stimuli`` of its default experiment ({input: ((t [s], value in the input's unit), ...)},
    linear in between, held after the last row) and ``default_signals`` (the shipped
    scenario whose signals are its defaults, or None)."""

    name: str
    slave: str
    loop: str | None = None
    events: bool = False
    stimuli: dict = field(default_factory=dict)
    default_signals: str | None = None

    @property
    def folder(self):
        """The FMU's folder."""
        return FOLDER / self.name

    @property
    def slave_path(self):
        """The pythonfmu slave script."""
        return self.folder / self.slave

    @property
    def slave_module(self):
        """The slave script's importable name (tests run the slave class in-process)."""
        return f"{__package__}.{self.name}.{Path(self.slave).stem}"

    @property
    def c_model(self):
        """The C family's adapter, ``<Model>.c``."""
        return self.folder / f"{self.name}.c"

    @property
    def page(self):
        """The model's page of ``documentation/index.html`` (an HTML fragment)."""
        return self.folder / PAGE_FILE


def _stimuli(table, path):
    """{input: ((t, value), ...)} of the ``[stimuli]`` table: rows of two finite numbers,
    times rising."""
    stimuli = {}
    for name, rows in table.items():
        if not (isinstance(rows, list) and rows and all(
                isinstance(row, list) and len(row) == 2
                and all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)
                        for x in row) for row in rows)):
            raise ValueError(f"{path}: stimuli.{name} must be rows [t s, value] of finite "
                             f"numbers, got {rows!r}")
        times = [float(t) for t, _ in rows]
        if any(later < earlier for earlier, later in zip(times, times[1:])):
            raise ValueError(f"{path}: stimuli.{name}: the times must rise, got {times}")
        stimuli[name] = tuple((float(t), float(value)) for t, value in rows)
    return stimuli


def read_declaration(name, folder=FOLDER):
    """The :class:`Declaration` of the FMU ``name`` from ``folder/name/fmu.toml``; raises
    ValueError naming the file and the key for a missing folder or file, an unknown key, a
    value of the wrong type, or a slave, adapter or page that is not in the folder."""
    path = Path(folder) / name / DECLARATION_FILE
    document = read_toml(path, ValueError, "FMU declaration")
    for key, value in document.items():
        if key not in _TYPES:
            raise ValueError(f"{path}: unknown key {key!r}; expected {', '.join(_TYPES)}")
        if not isinstance(value, _TYPES[key]):
            raise ValueError(f"{path}: {key} must be a {_TYPES[key].__name__}, got {value!r}")
    if "slave" not in document:
        raise ValueError(f"{path}: no slave (the pythonfmu slave script's file name)")
    declared = Declaration(name, document["slave"], document.get("loop"),
                           document.get("events", False),
                           _stimuli(document.get("stimuli", {}), path),
                           document.get("default_signals"))
    for what, file in (("slave", Path(folder) / name / declared.slave),
                       ("C adapter", Path(folder) / name / f"{name}.c"),
                       ("page", Path(folder) / name / PAGE_FILE)):
        if not file.is_file():
            raise ValueError(f"{path}: its {what} {file.name} is not in {file.parent}")
    return declared
