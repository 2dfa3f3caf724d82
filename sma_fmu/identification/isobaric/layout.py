"""Unknowns of the isobaric fit: where each lives in the vector.

Columns: the physical parameters, the strain offsets of every file, the lag of every file
(when fitted), then every file's temperature-profile knots. Starting values and bounds:
:mod:`sma_fmu.identification.isobaric.starts`.
"""
import math

import numpy as np

from sma_fmu.identification.isobaric.centres import SHARES, stage_laws
from sma_fmu.identification.measurements import MeasurementError
from sma_fmu.runtime.model_terms import domain_widths
from sma_fmu.runtime.parameters import ParameterError

__all__ = ["Layout", "InvalidParameter"]


class InvalidParameter(MeasurementError):
    """The fit reached a parameter the wire file refuses; ``detail`` names it and its range.
    A richer structure tried from a fit that holds (a second stage, separate widths, the
    centre law) is then not kept, rather than stopping the fit."""

    def __init__(self, paths, detail):
        super().__init__(f"{paths}: the fit reached an invalid parameter ({detail})")
        self.detail = detail


class Layout:
    """Columns of the unknowns, and their map onto the wire parameters.

    The centres of each stage are held by a centre law (``centres``: one per stage, a
    :class:`~.centres.LinearCentres` or, with ``centre_law="clausius-clapeyron"``, a
    :class:`~.centres.StrainFollowingCentres`): with one load the two centres at that load,
    with several the cooling line and the heating centre's lead over it at two loads, the
    lead bounded below by 0. :meth:`physical` maps the vector onto the parameter-file names
    (:meth:`transform` is its matrix). ``centre_law="linear"`` over a base file with shares
    writes them as 0.
    """

    def __init__(self, files, base, fit_slopes, absolute, with_resistance, fit_lag, stages=1,
                 loads=(), widths="separate", centre_law="linear"):
        self.stages = stages
        loads = list(loads) if fit_slopes else sorted(set(loads))[:1]
        measured = [f.thermocouple.values for f in files] or [np.array([-100.0, 400.0])]
        span = (min(float(t.min()) for t in measured), max(float(t.max()) for t in measured))
        self.centres = stage_laws(centre_law, loads, base, stages, span)
        self.linear_centres = centre_law == "linear" and any(getattr(base.terms, n) != 0.0
                                                             for n in SHARES)
        self.fit_slopes = self.centres[0].fit_slopes
        stresses = len({round(float(v), 9) for v in loads})
        self.phys = self.centres[0].names + (["nu_h", "nu_c"] if widths == "separate" else ["nu"])
        if stages == 2:
            self.phys += ["w2"] + self.centres[1].names + ["nu2_h", "nu2_c"]
        self.phys += ["l_MF"] + (["x_min"] if absolute else []) + ["alpha_P", "alpha_MF"]
        self.phys += (["span_ratio_0"] if stresses >= 2 else []) + \
            (["span_stress"] if stresses >= 3 else [])
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
        held = set()
        for law in self.centres:
            out.update(law.parameters(u))
            held.update(law.names)
        for name, value in u.items():
            if name not in held:
                out[name] = value
        widths = domain_widths(out)   # one width for both directions, or two and their nu
        out.pop("nu", None)
        out.update(widths)
        return out

    def settle(self, vector, base_name):
        """Choices made after the fit (the one-load slopes, :meth:`LinearCentres.settle`);
        returns the notes saying what was chosen and why."""
        u = dict(zip(self.phys, np.asarray(vector[:len(self.phys)], dtype=float).tolist()))
        for law in self.centres:
            law.settle(u, base_name)
        return [law.slope_note for law in self.centres if law.slope_note]

    def centres_at(self, vector, load):
        """[(heating, cooling) centre [degC] of each stage] at ``load`` [kg]."""
        u = dict(zip(self.phys, np.asarray(vector[:len(self.phys)], dtype=float).tolist()))
        return [law.centre_at(u, load) for law in self.centres]

    def transform(self, vector):
        """(names, matrix): d physical / d unknowns; by unit steps where every centre law is
        linear (exact), else by central differences of relative step 1e-6."""
        names = [n for n in self.physical(vector) if n != "nu"]
        base = self.physical(vector)
        linear = all(law.linear for law in self.centres)
        matrix = np.zeros((len(names), len(self.phys)))
        for j in range(len(self.phys)):
            x = np.array(vector[:len(self.phys)], dtype=float)
            step = 1.0 if linear else 1e-6 * max(abs(x[j]), 1.0)
            moved = x.copy()
            moved[j] += step
            after = self.physical(moved)
            if linear:
                matrix[:, j] = [after[n] - base[n] for n in names]
                continue
            moved[j] = x[j] - step
            before = self.physical(moved)
            matrix[:, j] = [(after[n] - before[n]) / (2.0 * step) for n in names]
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
            raise InvalidParameter(self.paths, detail) from None

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
