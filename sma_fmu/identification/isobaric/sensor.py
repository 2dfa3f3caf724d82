"""The thermocouple and the wire: when the wire's lag can be fitted, and what it does to the
hysteresis.

A first-order lag tau of the wire behind the thermocouple moves each branch along the
temperature axis by its ramp rate times tau: heating up by r_h tau, cooling down by
r_c tau. The hysteresis the thermocouple sees is therefore H_wire + (r_h + r_c) tau. When
every cycle crosses its transformation at the same rates (one furnace programme, or a wire
heated and cooled the same way each cycle), a lag and a wider hysteresis give the same
curves, and a fitted lag takes whatever part of the hysteresis the model's shape
misses: on the shared raw 100-cycle file a lag of 2.6 samples took the wire's hysteresis
from the thermocouple's 14.6 K down to 3.2 K. Only cycles that cross at different rates
tell the two apart (H_k = H_wire + (r_h,k + r_c,k) tau is then a line with a slope).

So ``--lag auto`` fits the lag only when every file holds two complete cycles or more *and*
the sum of the heating and cooling ramp rates r_h + r_c spreads by RATE_SPREAD or more
over its cycles ((90th - 10th percentile) / median); otherwise the wire's temperature is the
thermocouple's, and the report says how much a lag of one unit would narrow the
hysteresis (:func:`lag_sensitivity`). ``--lag fit`` fits it anyway (a transformation that
runs on past the turning points can also tell it apart).
"""
import numpy as np

from sma_fmu.runtime.constants import HEATING

__all__ = ["crossing_rates", "choose_lag", "lag_sensitivity", "RATE_SPREAD"]

RATE_SPREAD = 0.25


def crossing_rates(f):
    """{cycle: {direction: rate}}: the ramp rate of each complete branch [K per s, or per
    sample]: its thermocouple profile's swing between a quarter and three quarters of the
    branch's time, over that time (the programme's rate, not the local one, which a
    latent-heat plateau at the transformation makes noisy)."""
    values = f.thermocouple.values
    axis = f.data.time if f.data.time is not None else np.arange(values.size, dtype=float)
    out = {}
    for b in f.data.branches:
        if not b.complete or b.stop - b.start < 8:
            continue
        first = b.start + (b.stop - b.start) // 4
        last = b.start + 3 * (b.stop - b.start) // 4
        rate = abs(values[last] - values[first]) / max(axis[last] - axis[first], 1e-300)
        out.setdefault(b.cycle, {})[b.direction] = float(rate)
    return out


def _sums(f):
    return [r[1] + r[-1] for r in crossing_rates(f).values() if 1 in r and -1 in r]


def choose_lag(prepared, option):
    """("fit" or "none", note) for ``option`` "auto", "fit" or "none" (note: why, for auto)."""
    if option != "auto":
        return option, ""
    fewest = min(sum(1 for b in f.data.branches if b.complete and b.direction == HEATING)
                 for f in prepared)
    if fewest < 2:
        return "none", ("--lag auto: no lag fitted, as a file holds a single complete cycle (one "
                        "ramp rate: a lag cannot be told from a wider hysteresis); --lag fit "
                        "fits it anyway")
    spreads = []
    for f in prepared:
        sums = np.array(_sums(f))
        low, middle, high = np.percentile(sums, [10, 50, 90]) if sums.size else (0.0, 1.0, 0.0)
        spreads.append((high - low) / middle if middle > 0 else 0.0)
    if min(spreads) >= RATE_SPREAD:
        return "fit", (f"--lag auto: lag fitted, as the cycles cross their transformation at "
                       f"rates that differ by {100 * min(spreads):.0f} % or more")
    return "none", (f"--lag auto: no lag fitted: every cycle crosses its transformation at "
                    f"about the same rates (spread {100 * min(spreads):.0f} %, under "
                    f"{100 * RATE_SPREAD:.0f} %), so a lag cannot be told from a wider "
                    f"hysteresis; the wire's temperature is the thermocouple's (--lag fit "
                    f"fits it anyway)")


def lag_sensitivity(f):
    """Median r_h + r_c over the cycles [K per unit of lag]: how much a lag of one second
    (one sample without a time column) would narrow the wire's hysteresis."""
    sums = _sums(f)
    return float(np.median(sums)) if sums else float("nan")
