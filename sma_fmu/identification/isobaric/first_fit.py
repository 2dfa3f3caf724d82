"""The first fit: the model against the strain at the thermocouple's own temperature profile.

The joint fit (:mod:`~.fit`) moves the temperature profile's knots with the parameters.
Started far from the answer, the strain's pull on thousands of knots can bend the profile
into a valley where it, not the model, explains the strain (a heating branch 25 K off on the
shared raw file). So the parameters are found first with the profile held: the wire
temperature is the thermocouple profile fitted to the temperature alone (lagged when a lag
is fitted), and each strain residual is weighted by its effective variance,

    (model - strain) / sqrt(sigma_strain^2 + (d model/dT)^2 sigma_profile^2),

sigma_profile the profile's own standard error at the sample
(:func:`~.profile.pointwise_error`). On the steep part of a branch this measures the misfit
along the temperature axis, elsewhere along the strain axis. The weights are held during
one Levenberg-Marquardt run and renewed from its result (``ROUNDS`` times at most). Only
the parameters, offsets and lags are unknowns here (about 120 for a 100-cycle file, not
thousands), so this fit is cheap: the fit uses it to choose widths and stages, to find the
outlier cycles and the lag's valley, and as the start of the joint fit.
"""
import numpy as np
from scipy import sparse

from sma_fmu.identification.isobaric.jacobian import (file_model, model_columns,
                                                      scalar_sensitivities, sparse_rows)
from sma_fmu.identification.isobaric.lag import lag_derivative, lagged
from sma_fmu.identification.isobaric.profile import wire_rows
from sma_fmu.identification.isobaric.solver import levenberg_marquardt

__all__ = ["first_fit", "ROUNDS"]

ROUNDS = 2              # runs at most, the weights renewed before the second
ROUND_CHANGE = 1e-3     # stop renewing when the cost moves less than this, relative


def _state(x, layout, f):
    """(thermocouple profile, tau, wire, direction, level) of file ``f``."""
    tau = x[layout.lags[f.index]] if layout.lags[f.index] is not None else 0.0
    wire = lagged(f.thermocouple.values, tau, f.step)
    direction, level, _ = wire_rows(wire, f.data.branches, f.per_cycle)
    return f.thermocouple.values, tau, wire, direction, level


def _columns(x, layout, prepared, sensitivities=None):
    """Per file: (state, model columns) at ``x``."""
    if sensitivities is None:
        sensitivities = scalar_sensitivities(x, layout, [f.data.load for f in prepared])
    out = []
    for f in prepared:
        state = _state(x, layout, f)
        out.append((state, model_columns(x, layout, f, state[2], state[3], state[4],
                                         sensitivities)))
    return out


def _weights(x, layout, prepared):
    """Per file: {"strain", "resistance"}: 1/effective sigma of each sample (times its weight)."""
    out = []
    for f, (_, columns) in zip(prepared, _columns(x, layout, prepared)):
        entry = {}
        for key in ("strain", "resistance"):
            if columns[key] is None:
                continue
            spread = np.hypot(f.sigma[key], columns[f"{key}_T"] * f.tc_error)
            entry[key] = f.weight / spread
        out.append(entry)
    return out


def first_fit(prepared, layout, x0, lower, upper, max_evaluations=200, ftol=1e-8,
              weights=None, tick=None, rounds=ROUNDS):
    """(Solution over the first ``len(layout.reported)`` unknowns, the weights it used).

    ``weights`` (from an earlier call, or None) are renewed after each run, ``rounds`` runs
    at most; ``tick`` (callable or None) hears of every model evaluation."""
    k = len(layout.reported)

    def residuals(x):
        if tick is not None:
            tick()
        parts = []
        for f, w in zip(prepared, weights):
            _, _, wire, direction, level = _state(x, layout, f)
            strain, resistance = file_model(layout.params(x), f.data, wire,
                                            layout.levels(x, f.index), direction, level,
                                            f.per_cycle)
            parts.append(w["strain"] * (strain - f.data.strain))
            if resistance is not None:
                parts.append(w["resistance"] * (resistance - f.data.resistance))
        return np.concatenate(parts)

    def jacobian(x):
        blocks = []
        for f, w, (state, columns) in zip(prepared, weights, _columns(x, layout, prepared)):
            profile, tau, _, _, _ = state
            lag = layout.lags[f.index]
            d_tau = lag_derivative(profile, tau, f.step) if lag is not None else None
            for key in ("strain", "resistance"):
                if columns[key] is None:
                    continue
                n = profile.size
                extra = [] if d_tau is None else \
                    [(np.arange(n), np.full(n, lag), columns[f"{key}_T"] * d_tau)]
                block = sparse_rows(columns[f"{key}_phys"],
                                    columns["offsets"] if key == "strain" else None, extra, n, k)
                blocks.append(sparse.diags(w[key]) @ block)
        return sparse.vstack(blocks).tocsr()

    x = np.clip(np.asarray(x0[:k], dtype=float), lower[:k], upper[:k])
    if weights is None:
        weights = _weights(x, layout, prepared)
    solution = None
    for round_ in range(rounds):
        if round_:
            weights = _weights(x, layout, prepared)
        previous = solution
        solution = levenberg_marquardt(residuals, jacobian, x, lower[:k], upper[:k],
                                       max_evaluations, ftol=ftol)
        x = solution.x
        if previous is not None and \
                abs(previous.cost - solution.cost) <= ROUND_CHANGE * previous.cost:
            break
    return solution, weights
