"""Unknowns of the isobaric fit: where each lives in the vector.

Columns: the physical parameters, the strain offsets of every file, the lag of every file
(when fitted), then every file's temperature-profile knots. Starting values and bounds:
:mod:`sma_fmu.identification.isobaric.starts`.
"""
import math

import numpy as np

from sma_fmu.identification.isobaric.centre_law import SHARE_STRESSES
from sma_fmu.identification.measurements import MeasurementError
from sma_fmu.runtime.model_terms import domain_widths
from sma_fmu.runtime.parameters import ParameterError

__all__ = ["Layout"]


class Layout:
    """Columns of the unknowns, and their map onto the wire parameters.

    The centres are held as the cooling centre (a_c, b_c) and the heating centre's lead over
    it, ``gap0`` = a_h - a_c at no load and, with two loads or more, ``gapF`` at the largest
    load, both bounded below by 0: so each stage's heating centre is never below its cooling
    centre anywhere between no load and the largest load. :meth:`physical` maps the vector
    onto the parameter-file names (a linear map; :meth:`transform` is its matrix). With the
    Clausius-Clapeyron centres (``cc_share_h``, ``cc_share_c``) gapF still sets b_h as below;
    the heating centre's lead at a load f is then gap0 + b_h f_h - b_c f_c (f_d of
    :func:`~sma_fmu.runtime.model_terms.centre_load`).
    """

    def __init__(self, files, base, fit_slopes, absolute, with_resistance, fit_lag, stages=1,
                 loads=(), widths="separate", centre_law="linear"):
        self.stages = stages
        self.top_load = max(loads) if loads else 0.0
        fit_slopes = fit_slopes and self.top_load > 0.0
        self.fit_slopes = fit_slopes
        stresses = len({round(float(v), 9) for v in loads})
        centres = ["a_c"] + (["b_c"] if fit_slopes else []) + ["gap0"] + \
            (["gapF"] if fit_slopes else [])
        self.phys = centres + (["nu_h", "nu_c"] if widths == "separate" else ["nu"])
        if stages == 2:
            self.phys += ["w2"] + [n.replace("a_c", "a2_c").replace("b_c", "b2_c")
                                   .replace("gap", "gap2_") for n in centres] + ["nu2_h", "nu2_c"]
        self.phys += ["l_MF"] + (["x_min"] if absolute else []) + ["alpha_P", "alpha_MF"]
        self.phys += (["span_ratio_0"] if stresses >= 2 else []) + \
            (["span_stress"] if stresses >= 3 else [])
        # the centre law (isobaric/centre_law.py): each direction's share, fitted with three
        # stresses or more (two centres per direction fix only a_d and b_d)
        self.phys += ["cc_share_h", "cc_share_c"] if centre_law == "clausius-clapeyron" \
            and stresses >= SHARE_STRESSES else []
        # linear centres asked for, over a --model file with the law on: switch it off
        self.linear_centres = centre_law == "linear" and (base.terms.cc_share_h != 0.0
                                                          or base.terms.cc_share_c != 0.0)
        self.phys += ["R_P", "R_MF"] if with_resistance else []
        self.offsets = []   # per file: (first column, count, level-0 fixed at zero)
        names = list(self.phys)
        for f in files:
            count = f.data.levels if f.per_cycle else 1
            fixed = f.data.absolute
            self.offsets.append((len(names), count - fixed, fixed))
            names += [f"offset_{f.index}_{level}" for level in range(fixed, count)]
        self.lags = []
        for f in files:
            self.lags.append(len(names) if fit_lag else None)
            names += [f"lag_{f.index}"] if fit_lag else []
        self.reported = names
        self.knots = []
        column = len(names)
        for f in files:
            self.knots.append(slice(column, column + f.profile.knot_count))
            column += f.profile.knot_count
        self.size = column
        self.base = base
        self.paths = ", ".join(str(f.data.path) for f in files)
        self.half_l = 0.5 * (base.l_F - base.l_M)
        self.half_r = 0.5 * (base.R_F - base.R_M)

    def physical(self, vector):
        """{parameter-file name: value} that the physical unknowns of ``vector`` set."""
        u = dict(zip(self.phys, np.asarray(vector[:len(self.phys)], dtype=float).tolist()))
        out = {}
        for stage, (a, b, g) in ((1, ("a", "b", "gap")), (2, ("a2", "b2", "gap2_"))):
            if f"{a}_c" not in u:
                continue
            b_c = u.get(f"{b}_c", getattr(self.base, "b_c"))
            gap0 = u[f"{g}0"]
            if self.fit_slopes:
                b_h = b_c + (u[f"{g}F"] - gap0) / self.top_load
            else:
                b_h = getattr(self.base, "b_h") + b_c - getattr(self.base, "b_c")
            out.update({f"{a}_h": u[f"{a}_c"] + gap0, f"{b}_h": b_h, f"{a}_c": u[f"{a}_c"],
                        f"{b}_c": b_c})
        for name, value in u.items():
            if not (name.startswith(("a_c", "b_c", "a2_c", "b2_c", "gap"))):
                out[name] = value
        widths = domain_widths(out)   # one width for both directions, or two and their nu
        out.pop("nu", None)
        out.update(widths)
        return out

    def transform(self, vector):
        """(names, matrix): d physical / d unknowns (exact: the map is linear)."""
        names = [n for n in self.physical(vector) if n != "nu"]
        base = self.physical(vector)
        matrix = np.zeros((len(names), len(self.phys)))
        for j in range(len(self.phys)):
            moved = np.array(vector[:len(self.phys)], dtype=float)
            moved[j] += 1.0
            after = self.physical(moved)
            matrix[:, j] = [after[n] - base[n] for n in names]
        return names, matrix

    def params(self, vector):
        """WireParameters of ``vector``; a non-finite or invalid value names the data files."""
        values = self.physical(vector)
        bad = [f"{k} = {v!r}" for k, v in values.items() if not math.isfinite(v)]
        if bad:
            raise MeasurementError(f"{self.paths}: the fit produced a non-finite parameter "
                                   f"({', '.join(bad)}); the data do not determine it")
        changes = {k: v for k, v in values.items() if k not in ("l_MF", "R_MF")}
        changes["l_M"], changes["l_F"] = values["l_MF"] - self.half_l, values["l_MF"] + self.half_l
        if self.linear_centres:
            changes["cc_share_h"] = changes["cc_share_c"] = 0.0
        if "R_MF" in values:
            changes["R_M"] = values["R_MF"] - self.half_r
            changes["R_F"] = values["R_MF"] + self.half_r
        try:
            return self.base.replace(**changes)
        except ParameterError as error:
            detail = str(error).split(": ", 1)[-1]
            raise MeasurementError(f"{self.paths}: the fit reached an invalid parameter "
                                   f"({detail})") from None

    def time_order(self, files):
        """Column order for the sparse solves: every file's offsets and knots by the sample
        where they act, file after file, then the physical unknowns and the lags."""
        key = np.full(self.size, np.inf)
        for f in files:
            base = f.index * (f.data.temperature.size + 1.0)
            key[self.knots[f.index]] = base + f.profile.knots
            first, count, fixed = self.offsets[f.index]
            starts = {}
            for b in f.data.branches:
                starts.setdefault(b.level if f.per_cycle else 0, b.start)
            for level in range(fixed, count + fixed):
                key[first + level - fixed] = base + starts.get(level, f.data.temperature.size)
        return np.argsort(key, kind="stable")

    def levels(self, vector, index):
        first, count, fixed = self.offsets[index]
        return np.concatenate([[0.0] * fixed, vector[first:first + count]])
