"""Where an isobaric fit's strain residual sits: by branch direction and phase, and by cycle.

A verdict "does not explain the data" says how large the strain residual is, not where. The
same residual as the verdict's (the joint fit's wire temperature, left-out cycles' rows
excluded) is split by the direction of the wire's branch and the model's transformed share
q at the row: the austenite end (q < END_SHARE), the transformation, the martensite end
(q > 1 - END_SHARE); and by cycle. Each part gives its rows, its RMS, that RMS over the
file's strain noise (the verdict's: the estimate, or the file's quantisation where that is
larger, :mod:`~.resolution`), and its share of the file's sum of squared residuals (the
shares add up to 1), so a misfit at the ends of the branches (a shape or a thermal
expansion the model lacks there) is told from one in the transformation or in a few cycles.
"""
import numpy as np

from sma_fmu.identification.isobaric.jacobian import file_model
from sma_fmu.runtime.constants import COOLING, HEATING

__all__ = ["END_SHARE", "strain_parts", "parts_line"]

END_SHARE = 0.02        # q below this: austenite end; above 1 - this: martensite end
_PHASES = ("austenite end", "transformation", "martensite end")


def _part(residual, rows, noise, total):
    """rows, RMS [1], RMS/noise, share of ``total``; RMS and ratio None for a part without
    rows (a file with no martensite end, say), the share 0."""
    squares = float(np.sum(residual[rows] ** 2))
    rms = float(np.sqrt(squares / rows.sum())) if rows.any() else None
    return {"rows": int(rows.sum()), "rms": rms, "ratio": None if rms is None else rms / noise,
            "share": squares / total if total > 0 else 0.0}


def strain_parts(prepared, layout, x, states):
    """Per file: {"parts": [{"direction", "phase", "rows", "rms" [1], "ratio", "share"}],
    "cycles": [{"cycle", "rows", "rms", "ratio", "share"}]} of the strain residual at the
    solution ``x``, whose per-file ``states`` (``jacobian.file_state``) the caller has (rows
    of left-out cycles excluded, as in the residual RMS; a part without rows has RMS and
    ratio None and share 0)."""
    params = layout.params(x)
    out = []
    for f, (_, _, wire, direction, level, bounds) in zip(prepared, states):
        strain, _, q = file_model(params, f.data, wire, layout.levels(x, f.index), direction,
                                  level, f.per_cycle, share=True)
        residual = strain - f.data.strain
        kept = f.weight > 0
        noise = f.judged["strain"]
        total = float(np.sum(residual[kept] ** 2))
        phase = np.where(q < END_SHARE, 0, np.where(q > 1.0 - END_SHARE, 2, 1))
        parts = []
        for d, word in ((HEATING, "heating"), (COOLING, "cooling")):
            for index, name in enumerate(_PHASES):
                rows = kept & (direction == d) & (phase == index)
                parts.append({"direction": word, "phase": name,
                              **_part(residual, rows, noise, total)})
        cycle = np.zeros(residual.size, dtype=int)
        for index, b in enumerate(f.data.branches):
            cycle[bounds[index]:bounds[index + 1]] = b.cycle
        cycles = [{"cycle": int(c), **_part(residual, kept & (cycle == c), noise, total)}
                  for c in sorted(set(cycle[kept].tolist()))]
        out.append({"parts": parts, "cycles": cycles})
    return out


def parts_line(name, entry, count=3):
    """One console line: the ``count`` parts holding most of the squared strain residual."""
    parts = sorted((p for p in entry["parts"] if p["rows"]), key=lambda p: -p["share"])
    text = "; ".join(f"{p['direction']} {p['phase']} {p['ratio']:.2g}x ({100 * p['share']:.0f} %)"
                     for p in parts[:count])
    return (f"{name}: strain residual by part (RMS over its noise, share of the "
            f"squares): {text}")
