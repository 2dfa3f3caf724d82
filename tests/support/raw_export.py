"""A synthetic raw machine export of an isobaric test, with the quirks a test machine writes.

Made from :func:`sma_fmu.identification.isobaric.synthetic.isobaric_table` (the reference wire
through a seeded temperature programme), then written as a machine would:

- a preamble of quoted lines (title, specimen, method, operator, an empty line);
- quoting: every row written again as one quoted cell, its own quotes doubled (``"rows"``:
  the column row's names are quoted inside, the numbers not; split at its commas, the last
  cell of a row reads ``170.759"``), every cell quoted (``"cells"``), or none;
- a load ramp first: ``ramp_rows`` rows at the programme's first temperature, the stress
  rising from 0.5 MPa to the test's, the extension with it; ``unloading_rows`` at the end;
- time in hours written to 0.001 h (3.6 s): with a sample every 1.5 s each stamp repeats;
- extension [mm] from the start of the ramp over ``gauge_m``, not strain;
- a stress column [MPa] written with ``stress_column_mpa`` (default: the test's stress).

:func:`raw_export` returns the text and what a correct reading must give.
"""
import csv
import io
from dataclasses import dataclass

import numpy as np

from sma_fmu.identification.isobaric.synthetic import (IsobaricProgramme, isobaric_table,
                                                       load_of_stress)

__all__ = ["RawExport", "raw_export", "NAMES", "PREAMBLE"]

NAMES = ("Time (h)", "Temperature (°C)", "Extension (mm)", "Stress (MPa)")
PREAMBLE = ("Test report", "Specimen: NiTi wire, 0.15 mm", "Method: isobaric thermal cycling",
            "Operator: lab", "")
_DECIMALS = {"Time (h)": 3, "Temperature (°C)": 2, "Extension (mm)": 4, "Stress (MPa)": 3}


@dataclass(frozen=True)
class RawExport:
    """What the export holds (units in names)."""

    stress_mpa: float = 170.0
    stress_column_mpa: float = None      # written in the stress column (default: stress_mpa)
    quoting: str = "rows"                # "rows", "cells" or "none"
    ramp_rows: int = 120
    unloading_rows: int = 0
    start_h: float = 0.157               # the machine's clock at the first row
    time_decimals: int = 3
    gauge_m: float = 0.8                 # the length the machine's extension is over
    elastic: float = 3e-3                # strain the load puts on before any cycling [1]
    seed: int = 5
    cycles: int = 3
    points: int = 3000


def _cells(values, decimals):
    return [f"{v:.{decimals}f}" for v in values]


def raw_export(params, export=RawExport()):
    """(text, truth) of a raw export; truth: {"names", "rows" (cell text per column name, the
    constant-load rows only), "first_line" (line of the first row at constant load),
    "last_line", "ramp_lines" (first, last), "stress_MPa", "step_s" (true sample step)}."""
    load = load_of_stress(export.stress_mpa, params.diameter)
    programme = IsobaricProgramme(t_low=20.0, t_high=130.0, rate=10.0, cycles=export.cycles,
                                  dwell=60.0, points=export.points, noise_K=0.3,
                                  noise_strain=2e-5, seed=export.seed)
    columns, _ = isobaric_table(params, load, programme, strain_unit="fraction")
    rng = np.random.default_rng(export.seed)
    step = float(columns["time_s"][1] - columns["time_s"][0])
    ramp, unload = export.ramp_rows, export.unloading_rows
    n = ramp + export.points + unload
    time_s = 3600.0 * export.start_h + step * np.arange(n)
    written = export.stress_column_mpa or export.stress_mpa
    stress = np.full(n, written) + 0.3 * rng.standard_normal(n)
    share = np.ones(n)
    share[:ramp] = np.linspace(0.5 / written, 1.0, ramp, endpoint=False) if ramp else []
    share[n - unload:] = np.linspace(1.0, 0.5 / written, unload + 1)[1:] if unload else []
    stress = np.where(share < 1.0, written * share, stress)
    strain = np.concatenate([np.full(ramp, columns["strain"][0]), columns["strain"],
                             np.full(unload, columns["strain"][-1])])
    zero = columns["strain"][0] - export.elastic     # the extension is zero with no load
    extension_mm = 1e3 * export.gauge_m * (strain - zero) * np.where(share < 1.0, share, 1.0)
    temperature = np.concatenate([np.full(ramp, programme.t_low) + 0.3 * rng.standard_normal(ramp),
                                  columns["temperature_C"],
                                  np.full(unload, columns["temperature_C"][-1])])
    decimals = dict(_DECIMALS, **{"Time (h)": export.time_decimals})
    table = {name: _cells(values, decimals[name]) for name, values in
             zip(NAMES, (time_s / 3600.0, temperature, extension_mm, stress))}
    lines = [line if export.quoting == "none" else _csv([line], csv.QUOTE_ALL)
             for line in PREAMBLE] + [_line(NAMES, export.quoting, header=True)]
    lines += [_line(row, export.quoting) for row in zip(*table.values())]
    first = len(PREAMBLE) + 2 + ramp
    kept = slice(ramp, ramp + export.points)
    return "\n".join(lines) + "\n", {
        "names": NAMES, "rows": {name: cells[kept] for name, cells in table.items()},
        "first_line": first, "last_line": first + export.points - 1,
        "ramp_lines": (first - ramp, first - 1), "stress_MPa": written, "step_s": step}


def _csv(row, quoting):
    stream = io.StringIO()
    csv.writer(stream, quoting=quoting, lineterminator="").writerow(row)
    return stream.getvalue()


def _line(row, quoting, header=False):
    """One row as written: plain, every cell quoted, or the row (names quoted, numbers not)
    written again as one quoted cell."""
    if quoting == "none":
        return ",".join(row)
    cells = _csv(row, csv.QUOTE_ALL if quoting == "cells" or header else csv.QUOTE_MINIMAL)
    return cells if quoting == "cells" else _csv([cells], csv.QUOTE_ALL)
