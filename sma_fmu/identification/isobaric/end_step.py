"""A strain step at a file's start or end that no temperature explains: found and left out.

Raw files can end (or start) with rows after a step in the strain that the test, not the
wire, made: an extensometer that slips or is re-zeroed, a clip taken off, a sheet's rows
pasted from elsewhere. The raw NiTiHf workbook of the public set (docs/identification.md,
"Workbooks") has one in every sheet: its last 49 rows sit 0.20-0.21 % strain above the rest,
one step 14-26 times any other step of the sheet, at the hot end where the strain is flat.
A model driven by temperature has no such step, and those rows would bend the fit and the
data's own hot baseline (its heating half-strain temperature read 273.5 degC at 50 MPa,
where the transformation runs through 150-170 degC).

The rule: the largest strain step between two rows is more than :data:`STEP_FACTOR` times
every other step of the file, and the rows on one side of it are the file's first or last
rows and at most :data:`END_SHARE` of them. Those rows are left out with a note naming
the lines, the step and the temperature there. In the lab files at hand (Flexinol,
Karaman, Alex, UNT, ASMADA, Walgren) the largest step is at most 1.27 times the next (the
steepest part of a transformation is several rows long), so the factor 5 leaves every one
of them alone. A step inside the file is left to the residual-strain offsets.
"""
import numpy as np

__all__ = ["STEP_FACTOR", "END_SHARE", "end_step"]

STEP_FACTOR = 5.0     # the step against every other step of the file [1]
END_SHARE = 0.05      # at most this share of the rows may lie beyond the step [1]


def end_step(strain, temperature, lines):
    """(kept rows as a slice, note or None) of a file's ``strain`` [1] and ``temperature``
    [degC] per row, ``lines`` its line numbers; the note names the rows left out."""
    n = strain.size
    whole = slice(0, n)
    if n < 3:
        return whole, None
    steps = np.abs(np.diff(strain))
    k = int(np.argmax(steps))
    others = np.delete(steps, k)
    if not steps[k] > STEP_FACTOR * others.max():
        return whole, None
    before, after = k + 1, n - k - 1          # rows on each side of the step
    if after <= END_SHARE * n and after <= before:
        kept, gone = slice(0, k + 1), (k + 1, n - 1)
        where = "last"
    elif before <= END_SHARE * n:
        kept, gone = slice(k + 1, n), (0, k)
        where = "first"
    else:
        return whole, None
    count = gone[1] - gone[0] + 1
    ratio = steps[k] / others.max()
    note = (f"lines {lines[gone[0]]}-{lines[gone[1]]} (the {where} {count} rows) left out: the "
            f"strain steps by {100.0 * (strain[k + 1] - strain[k]):+.3g} % strain between "
            f"lines {lines[k]} and {lines[k + 1]} at {temperature[k]:.4g} degC, {ratio:.3g} "
            f"times any other step of the file; a wire's strain does not step where its "
            f"temperature does not (an extensometer or test event)")
    return kept, note
