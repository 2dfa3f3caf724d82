"""Which model the data support, and where the joint fit starts: the first fit's choices of
the lag's valley, the outlier cycles, the widths and the stages (:mod:`~.first_fit`), the
joint fit's starts, and its second look at a richer structure the first fit did not keep.

Richer models are kept only when they lower the cost by STAGE_GAIN_MIN (a second stage also
needs w2 > STAGE_SHARE_MIN, and the first fit keeps one only when that fit converged; else
the joint fit decides): with a fitted lag, separate widths blur the lag against the
centres, so one width comes first. The joint fit tries a second stage from its one-stage
solution split in two halves (:mod:`~.split`). The centre law's shares come last
(:func:`law_look`).
"""
import time
from dataclasses import dataclass

import numpy as np
from scipy import sparse

from sma_fmu.identification.isobaric.first_fit import ROUNDS, first_fit
from sma_fmu.identification.isobaric.jacobian import file_jacobian, scalar_sensitivities
from sma_fmu.identification.isobaric.layout import InvalidParameter
from sma_fmu.identification.isobaric.outcome import residual_blocks
from sma_fmu.identification.isobaric.outliers import mark_outliers
from sma_fmu.identification.isobaric.solver import levenberg_marquardt
from sma_fmu.identification.isobaric.split import split_stage
from sma_fmu.identification.isobaric.starts import starts
from sma_fmu.runtime.constant_load import hysteresis_centre, second_centre
from sma_fmu.runtime.constants import COOLING, HEATING
from sma_fmu.runtime.model_terms import domain_widths

__all__ = ["Clock", "Joint", "joint", "choose", "joint_starts", "second_look", "simpler_look",
           "law_look",
           "with_head",
           "STAGE_SHARE_MIN", "STAGE_GAIN_MIN", "JOINT_FTOL", "FIRST_FTOL", "SCAN_EVALUATIONS",
           "LAG_STARTS"]

STAGE_SHARE_MIN = 1e-3  # a second stage holding less than this share of M is not kept
STAGE_GAIN_MIN = 0.01   # nor one that lowers the cost by less than this fraction
JOINT_FTOL = 1e-7       # the joint fit has converged when 3 steps in a row gain less, relative
FIRST_FTOL = 1e-6       # the first fit only chooses and starts: a looser tolerance
SCAN_EVALUATIONS = 6    # per starting lag before the full fit
LAG_STARTS = (1 / 300, 1 / 100, 1 / 50, 1 / 25, 1 / 12, 1 / 6)   # of a cycle


class Clock:
    """Counts model evaluations and moves a progress bar (``meter()`` returns a tqdm-like bar;
    None: no bar)."""

    def __init__(self, meter):
        self.began = time.perf_counter()
        self.evaluations = 0
        self.bar = meter() if meter is not None else None

    def stage(self, text):
        if self.bar is not None:
            self.bar.set_description_str(text)

    def tick(self, cost=None):
        self.evaluations += 1
        if self.bar is not None:
            self.bar.update(1)
            if cost is not None:
                self.bar.set_postfix_str(f"cost {cost:.6g}", refresh=False)

    def close(self):
        if self.bar is not None:
            self.bar.close()


def joint(prepared, layout, lower, upper, clock):
    """(residuals, jacobian, solve, order) of the joint fit of one layout."""
    order = layout.time_order(prepared)
    loads = [f.data.load for f in prepared]

    def residuals(x):
        out = np.concatenate(residual_blocks(x, layout, prepared))
        clock.tick(0.5 * float(out @ out))
        return out

    def jacobian(x):
        sensitivities = scalar_sensitivities(x, layout, loads)
        return sparse.vstack([b for f in prepared
                              for b in file_jacobian(x, layout, f, sensitivities)]).tocsr()

    def solve(x0, evaluations):
        return levenberg_marquardt(residuals, jacobian, x0, lower, upper, evaluations,
                                   ftol=JOINT_FTOL, order=order)
    return residuals, jacobian, solve, order


def _carry(old_layout, old_x, layout, vector):
    """``vector`` with every unknown the two layouts share taken from ``old_x`` (one width
    nu gives both nu_h and nu_c: :func:`~sma_fmu.runtime.model_terms.domain_widths`)."""
    out = vector.copy()
    old = dict(zip(old_layout.phys, old_x))
    old.update(domain_widths(old))
    for i, name in enumerate(layout.phys):
        if name in old:
            out[i] = old[name]
    k_old, k = len(old_layout.phys), len(layout.phys)
    out[k:len(layout.reported)] = old_x[k_old:len(old_layout.reported)]
    if len(old_x) == old_layout.size:     # a joint solution: its profile's knots too
        out[len(layout.reported):] = old_x[len(old_layout.reported):]
    return out


@dataclass
class _Trial:
    """A layout and its first fit: start vector and bounds (all unknowns), solution, weights."""

    layout: object
    vector: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    solution: object = None
    weights: list = None


def _first(prepared, trial, clock, evaluations=100, rounds=ROUNDS):
    """``trial`` with its first fit done (at most ``evaluations`` per run, ``rounds`` runs)."""
    trial.solution, trial.weights = first_fit(prepared, trial.layout, trial.vector, trial.lower,
                                              trial.upper, evaluations, FIRST_FTOL,
                                              tick=clock.tick, rounds=rounds)
    return trial


def choose(prepared, base, layout_of, kind, widths, stages, lagged, outliers, clock):
    """The first fit: lag valley, outlier cycles, widths and stages. Returns (trial, stages,
    width kind, outlier cycles, the richer structures it did not keep: "widths", "stages")."""
    def trial_of(count, width_kind, fraction=0.01):
        layout = layout_of(count, width_kind)
        return _Trial(layout, *starts(prepared, layout, base, fraction))

    clock.stage("first fit")
    # on the data's own starting model first: a poor first fit can hide an odd cycle
    left_out = mark_outliers(prepared, layout_of(1, kind), trial_of(1, kind).vector,
                             outliers == "leave-out")
    if lagged:    # short fits from lags of 1/300 to 1/6 of a cycle; the best two go on
        scans = [_first(prepared, trial_of(1, kind, fraction), clock, SCAN_EVALUATIONS, 1)
                 for fraction in LAG_STARTS]
        scans.sort(key=lambda t: t.solution.cost)
        best = [_first(prepared, _Trial(t.layout, with_head(t.vector, t.solution.x), t.lower,
                                        t.upper), clock) for t in scans[:2]]
    else:
        best = [_first(prepared, trial_of(1, kind), clock)]
    trial = min(best, key=lambda t: t.solution.cost)

    def outlying(trial):
        """``trial`` fitted again when its solution shows outlier cycles not yet left out (a
        poor fit hides them: a wider model can show more)."""
        found = mark_outliers(prepared, trial.layout, trial.solution.x, outliers == "leave-out")
        known = {(c["file"], c["cycle"]) for c in left_out}
        fresh = [c for c in found if (c["file"], c["cycle"]) not in known]
        left_out.extend(fresh)
        if fresh and outliers == "leave-out":
            trial = _first(prepared, _Trial(trial.layout, with_head(trial.vector, trial.solution.x),
                                            trial.lower, trial.upper), clock)
        return trial

    trial = outlying(trial)

    def richer(count, width_kind):
        """The richer layout from the kept one's solution, and from the data's own starts."""
        fresh = trial_of(count, width_kind)
        kept = with_head(trial.vector, trial.solution.x)
        carried = _Trial(fresh.layout, _carry(trial.layout, kept, fresh.layout, fresh.vector),
                         fresh.lower, fresh.upper)
        tries = []
        for candidate in [carried] + ([fresh] if count == 2 else []):
            try:    # a richer start that leaves the valid parameters is not a fit
                tries.append(_first(prepared, candidate, clock))
            except InvalidParameter:
                pass    # the joint fit's second look says why (second_look)
        return min(tries, key=lambda t: t.solution.cost) if tries else None

    rejected = []
    if widths == "auto":
        clock.stage("first fit: widths")
        wider = richer(1, "separate")
        if wider is not None and \
                wider.solution.cost <= (1.0 - STAGE_GAIN_MIN) * trial.solution.cost:
            trial, kind = outlying(wider), "separate"
        else:
            rejected.append("widths")
    if stages == 2:
        clock.stage("first fit: stages")
        wider = richer(2, kind)
        w2 = wider.solution.x[wider.layout.phys.index("w2")] if wider is not None else 0.0
        # a first fit that stopped at its limit has not settled the stage (it can be one
        # narrowing to a step): the joint fit's second look decides, from the split
        if w2 > STAGE_SHARE_MIN and wider.solution.status > 0 and \
                wider.solution.cost <= (1.0 - STAGE_GAIN_MIN) * trial.solution.cost:
            trial = outlying(wider)
        else:
            rejected.append("stages")
            stages = 1
    return trial, stages, kind, left_out, rejected


def joint_starts(prepared, trial, start, solve, lagged):
    """The joint fit's starts: the first fit's solution, and with a lag the two best of short
    joint fits from it with the lag at the first fit's value and at 1/300 to 1/6 of a cycle
    (the first fit holds a smoothed temperature, and can put the lag in another valley)."""
    start = np.clip(start, trial.lower, trial.upper)
    if not lagged:
        return [start]
    candidates = [start]
    for fraction in LAG_STARTS:
        x = start.copy()
        for f in prepared:
            column = trial.layout.lags[f.index]
            period = f.data.splitting.period_samples * f.step if f.data.splitting else 100 * f.step
            x[column] = min(fraction * period, trial.upper[column])
        candidates.append(x)
    scans = sorted((solve(x, SCAN_EVALUATIONS) for x in candidates), key=lambda s: s.cost)
    return [s.x for s in scans[:2]]


def _from_state(prepared, base, state, layout, clock, max_evaluations, shape=None):
    """The joint fit of ``layout`` started from ``state``'s solution (the unknowns both
    share carried over, :func:`_carry`; then ``shape(start)`` when given), as a
    :class:`Joint`; an InvalidParameter of its solve propagates. What the looks at another
    structure each start with."""
    vector, lower, upper = starts(prepared, layout, base)
    start = _carry(state.layout, state.solution.x, layout, vector)
    start = shape(start) if shape is not None else start
    _, jacobian, solve, order = joint(prepared, layout, lower, upper, clock)
    solution = solve(np.clip(start, lower, upper), max_evaluations)
    return Joint(layout, solution, jacobian, order, lower, upper, vector)


def _splitter(prepared, state, layout):
    """The start shaper that splits the one-stage joint fit ``state``'s stage in two halves
    for the two-stage ``layout`` (:func:`~.split.split_stage`, at the files' loads)."""
    loads = [f.data.load for f in prepared]
    return lambda start: split_stage(state.layout, state.solution.x, layout, start, loads)


def second_look(prepared, base, layout_of, state, kind, rejected, clock, max_evaluations):
    """The joint fit's word on each richer structure the first fit did not keep (the first
    fit holds the temperature, and on filtered files, whose noise estimates are tiny, that
    can hide what the joint fit sees): tried from the joint solution (a second stage from
    its stage split in two, :func:`_splitter`), kept when it lowers the joint cost by
    STAGE_GAIN_MIN. Returns (state, width kind, stages, notes)."""
    notes, stages = [], state.layout.stages
    for what in rejected:
        count, width_kind = (stages, "separate") if what == "widths" else (2, kind)
        layout = layout_of(count, width_kind)
        try:
            richer = _from_state(prepared, base, state, layout, clock, max_evaluations,
                                 None if what == "widths" else _splitter(prepared, state, layout))
        except InvalidParameter as error:
            notes.append(("a second stage" if what == "stages" else "separate heating and "
                          "cooling widths") + f" reached an invalid parameter ({error.detail}): "
                         + ("one stage" if what == "stages" else "one width") + " kept")
            continue
        solution = richer.solution
        if what == "stages":
            w2 = solution.x[richer.layout.phys.index("w2")]
            if w2 > STAGE_SHARE_MIN and \
                    solution.cost <= (1.0 - STAGE_GAIN_MIN) * state.solution.cost:
                state, stages = richer, 2
            else:
                notes.append(f"a second stage does not fit these data better (w2 = {w2:.3g}, "
                             f"cost {solution.cost:.6g} against {state.solution.cost:.6g} with "
                             f"one stage): one stage kept")
        elif solution.cost <= (1.0 - STAGE_GAIN_MIN) * state.solution.cost:
            state, kind = richer, width_kind
        else:
            notes.append(f"separate heating and cooling widths do not fit these data better "
                         f"(cost {solution.cost:.6g} against {state.solution.cost:.6g} with "
                         f"one): one width kept")
    return state, kind, stages, notes


def simpler_look(prepared, base, layout_of, state, kind, clock, max_evaluations):
    """One stage again when the joint fit with the first fit's second stage did not converge
    (a stage kept on a first fit that stopped at its limit can be all but empty and its
    centres loosely held): tried from that solution, kept when it converges, as a richer
    model must (:func:`law_look`). Returns (state, stages, note: "" when nothing changed)."""
    if state.solution.status > 0 or state.layout.stages == 1:
        return state, state.layout.stages, ""
    try:
        simpler = _from_state(prepared, base, state, layout_of(1, kind), clock, max_evaluations)
    except InvalidParameter:
        return state, 2, ""
    solution = simpler.solution
    if solution.status <= 0:
        return state, 2, ""
    w2 = state.solution.x[state.layout.phys.index("w2")]
    return (simpler, 1,
            f"a second stage did not converge in the joint fit ({state.solution.message}; "
            f"w2 = {w2:.3g}), one stage did (cost {solution.cost:.6g} against "
            f"{state.solution.cost:.6g}): one stage kept")


def _crossed_centres(params, loads):
    """The files' loads [kg] where a heating centre (either stage) lies below its cooling
    one, by the runtime's centres, as text ("" where none does)."""
    bad = [f"{load:g} kg" for load in loads
           for centre in (hysteresis_centre,) + ((second_centre,) if params.terms.two_stage
                                                 else ())
           if centre(load, HEATING, params) < centre(load, COOLING, params)]
    return ", ".join(dict.fromkeys(bad))


def law_look(prepared, base, layout_of, state, kind, clock, max_evaluations):
    """The joint fit with the strain-following centres (their shares fitted,
    :class:`~.centres.StrainFollowingCentres` from ``layout_of(stages, kind)``), started
    from the converged joint fit with linear centres (shares at 0: the same centres). Kept
    when it converged, lowers the joint cost by STAGE_GAIN_MIN and leaves every heating
    centre at or above its cooling one at each file's load. Returns (state, note: "" when
    kept, else why not)."""
    clock.stage("joint fit: centre law")
    try:
        law = _from_state(prepared, base, state, layout_of(state.layout.stages, kind), clock,
                          max_evaluations)
    except InvalidParameter as error:
        return state, (f"centres that follow the transformation strain reached an invalid "
                       f"parameter ({error.detail}): linear centres kept")
    old, solution = state.solution, law.solution
    crossed = _crossed_centres(law.layout.params(solution.x),
                               sorted({f.data.load for f in prepared}))
    if solution.status > 0 and solution.cost <= (1.0 - STAGE_GAIN_MIN) * old.cost and not crossed:
        return law, ""
    costs = f"cost {solution.cost:.6g} against {old.cost:.6g} with linear centres"
    if solution.status <= 0:
        why = f"did not converge ({solution.message}; {costs})"
    elif crossed and solution.cost <= (1.0 - STAGE_GAIN_MIN) * old.cost:
        why = f"would put the heating centre below the cooling one at {crossed} ({costs})"
    else:
        why = f"do not fit these data better ({costs})"
    return state, f"centres that follow the transformation strain {why}: linear centres kept"


@dataclass
class Joint:
    """A joint fit: its layout, solution, Jacobian function, order, bounds and start."""

    layout: object
    solution: object
    jacobian: object
    order: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    vector: np.ndarray


def with_head(vector, head):
    """``vector`` with its first entries replaced by ``head``."""
    out = np.array(vector, dtype=float)
    out[:len(head)] = head
    return out
