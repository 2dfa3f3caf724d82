"""A second stage started by splitting the fitted first one in two.

The two-stage model q = (1 - w2) q1 + w2 q2 is symmetric where both stages coincide: the
data cannot tell which stage should move which way. A second stage started on the first
one's centres (a broader copy, :mod:`~.starts`) leaves the fit to break that symmetry
itself, and it can slide instead into a stage of a percent or less that narrows towards a
step while the joint fit crawls after it (filtered NiTi files at 200/300/400 MPa: w2 =
0.008, its heating width narrowing from 4.6 K at the evaluation limit to 0.1 K, against a
sample spacing of 1.2 K, 2,074 evaluations to converge; from the split, w2 = 0.59 in 823
evaluations with a strain residual a third as large). The split breaks the symmetry as a
mixture model's split move does: the one-stage curve's two halves, each half the
transformation (w2 = 1/2) with its width, centred at its quartiles, tau -+ ln 3 T_c^2 / E
(where the logistic in 1/T passes 25 % and 75 %, to first order; E its energy, T_c its
centre [K]), per direction at the files' median load.
"""
import math

import numpy as np

from sma_fmu.identification.isobaric.terms import branch_scalars
from sma_fmu.runtime.constants import COOLING, HEATING
from sma_fmu.runtime.model_terms import domain_widths

__all__ = ["split_stage", "quartile_offsets", "SPLIT_SHARE"]

SPLIT_SHARE = 0.5       # each half holds half the transformation


def quartile_offsets(params, load):
    """{"h": K, "c": K}: how far the one-stage curve's 25 % and 75 % points lie from its
    centre on each branch at ``load`` [kg] (ln 3 T_c^2 / E, the logistic in 1/T)."""
    out = {}
    for key, direction in (("h", HEATING), ("c", COOLING)):
        s = branch_scalars(params, load, direction)
        out[key] = math.log(3.0) * float(s.centre1_K) ** 2 / float(s.energy1)
    return out


def split_stage(one_layout, one_x, layout, vector, loads):
    """``vector`` (a two-stage layout's start, the unknowns both share already carried over
    from the one-stage solution ``one_x`` of ``one_layout``) with the first stage split in
    two: stage 1 at the upper quartiles, stage 2 at the lower ones, w2 = SPLIT_SHARE, both
    with the first stage's widths. ``loads`` [kg]: the files' loads."""
    params = one_layout.params(one_x)
    physical = one_layout.physical(one_x)
    widths = domain_widths(physical)
    offsets = quartile_offsets(params, float(np.median(loads)))
    out = np.array(vector, dtype=float)
    for law, sign in zip(layout.centres, (1.0, -1.0)):
        lines = {key: (getattr(params, f"a_{key}") + sign * offsets[key], getattr(params, f"b_{key}"))
                 for key in ("h", "c")}
        for name, value in law.start(lines).items():
            out[layout.phys.index(name)] = value
    out[layout.phys.index("w2")] = SPLIT_SHARE
    out[layout.phys.index("nu2_h")] = widths["nu_h"]
    out[layout.phys.index("nu2_c")] = widths["nu_c"]
    return out
