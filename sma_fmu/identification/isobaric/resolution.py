"""The resolution a file's columns are written with, and the noise a verdict judges against.

The fit's noise estimates (:func:`~.files.noise_level`, the scatter of second differences)
weight the residuals. On a file that was filtered, or written with few digits, most second
differences are exactly zero and the estimate falls below what the file can show at all: a
value rounded to a step q carries a rounding error of q/sqrt(12) RMS (uniform on +-q/2).
The verdict, the strain residual parts and every "x its noise" text therefore judge the
residuals against the larger of the estimate and that quantisation floor; the fit's weights
keep the estimate.

The step is read from the text as written: the place of the last nonzero digit of each cell
(trailing zeros are padding: ``308.4050000`` is a 0.001 step), the finest over the column.
Not the smallest difference of the sorted unique values: that equals the step only where
the rows visit neighbouring levels, and overstates it on a fast ramp, a short file or
sparsely sampled levels, so a floor from it could hide a real misfit. The written digits can
only understate the step (a float written in full gives about 1e-17, a floor of nothing),
never overstate it.
"""
import math
from decimal import Decimal, InvalidOperation

from sma_fmu.identification.isobaric.starts import PROFILE_BOUND, PROFILE_TOLERANCE_K

__all__ = ["written_step", "quantisation", "judged_noise", "floor_notes", "smooth_note",
           "SENSOR_SCATTER"]

_QUANTITIES = {"temperature": "K", "strain": "", "resistance": "ohm"}
# the least scatter a lab's raw recording shows (a thermocouple or RTD read to 0.01 K, an
# extensometer to 1e-6 of strain), halved: a noise below it is a filter's remains or none
SENSOR_SCATTER = {"temperature_K": 0.005, "strain": 5e-7}
_UNITS = {"temperature_K": " K", "strain": ""}


def written_step(texts, decimal_comma=False):
    """The finest step a column's cells are written with, in the column's own unit: 10 to
    the place of the last nonzero digit, the smallest over ``texts``; 0.0 when every cell
    is zero or none is a plain number."""
    finest = None
    for text in texts:
        try:
            value = Decimal(text.strip().replace(",", ".") if decimal_comma else text.strip())
        except InvalidOperation:
            continue
        if not value.is_finite() or value.is_zero():
            continue
        place = value.normalize().as_tuple().exponent
        finest = place if finest is None else min(finest, place)
    return 0.0 if finest is None else 10.0 ** finest


def quantisation(step):
    """RMS rounding error [the step's unit] of values written to ``step``: step/sqrt(12)."""
    return step / math.sqrt(12.0)


def judged_noise(sigma, resolution):
    """(floors, judged): per quantity of ``sigma`` (the noise estimates), the quantisation
    of the file's ``resolution`` ({quantity: {"step": ...}} in the data's units; a quantity
    without one has floor 0) and the larger of estimate and floor."""
    floors = {key: quantisation(resolution.get(key, {}).get("step", 0.0)) for key in sigma}
    return floors, {key: max(sigma[key], floors[key]) for key in sigma}


def floor_notes(prepared):
    """One line per file and quantity whose noise was floored at the file's resolution:
    "noise floored at the file's resolution: 0.1 K written, 0.029 K"; one per file whose
    temperature shows no scatter at all, held (``held`` of :func:`~.fit.prepare`)."""
    notes = []
    for f in prepared:
        if getattr(f, "held", False):
            notes.append(f"{f.data.path.name}: the temperature shows no scatter (computed or "
                         f"resampled): the wire temperature is held at it, its profile's knots "
                         f"within {PROFILE_BOUND:g} standard errors of its own fit, not within "
                         f"the {PROFILE_TOLERANCE_K:g} K thermocouple tolerance")
        for key, unit in _QUANTITIES.items():
            if key in f.sigma and f.floor[key] > f.sigma[key]:
                written = f.data.resolution[key]
                column_unit = f" {written['unit']}" if written["unit"] not in ("", "fraction") \
                    else ""
                own = f" {unit}" if unit else ""
                notes.append(f"{f.data.path.name}: {key} noise floored at the file's resolution: "
                             f"{written['written']:.3g}{column_unit} written, "
                             f"{f.floor[key]:.2g}{own} (estimate {f.sigma[key]:.2g}{own})")
    return notes


def smooth_note(noise, rms):
    """A note when the noise judged against (``noise``, {"temperature_K", "strain", ...}) lies
    below :data:`SENSOR_SCATTER` ("" otherwise): the data were filtered or computed, so a
    ratio to that noise ("1898133.9x") says little, and the residuals ``rms`` are given in
    their own units instead."""
    below = [key for key, least in SENSOR_SCATTER.items()
             if noise.get(key) is not None and noise[key] < least]
    if not below:
        return ""
    what = lambda values, keys: ", ".join(   # noqa: E731
        f"{key.split('_')[0]} {values[key]:.3g}{_UNITS[key]}" for key in keys)
    return (f"the noise judged against ({what(noise, below)}) is below a lab sensor's scatter "
            f"({what(SENSOR_SCATTER, below)}): the data look filtered or computed, so a ratio "
            f"to it says little; judge the residual RMS in its units ("
            f"{what(rms, [k for k in SENSOR_SCATTER if rms.get(k) is not None])}) and the "
            f"half-strain temperatures below")
