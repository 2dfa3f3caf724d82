"""What the isobaric report says about the centre law (``--centre-law``): the centres'
standard errors whatever the law (:func:`centre_gradient`) and what was done with the shares
(:func:`law_note`).

The laws themselves are in :mod:`~.centres`: linear centres a_d + b_d f, or centres whose load
slope follows the transformation strain (Clausius-Clapeyron; the runtime's
:func:`~sma_fmu.runtime.model_terms.centre_load`: a share c_d = cc_share_d per direction).
With three stresses or more each direction's share is an unknown, bounded to [0, 1] and
fitted last, from the converged linear fit (:func:`~.structure.law_look`), and kept when it
lowers the cost by 1 %: where the transformation strain hardly changes over the stresses
(the Flexinol files: s from 0.67 to 0.95) the shares are not determined, and the linear
centres stay. With fewer stresses, two centres per direction fix only a_d and b_d, so the
shares stay from ``--model`` (0, linear, for every shipped file). ``linear`` switches a share
of ``--model`` off.
"""
import numpy as np

from sma_fmu.identification.isobaric.centres import SHARE_STRESSES
from sma_fmu.runtime.constant_load import hysteresis_centre
from sma_fmu.runtime.parameters import ParameterError

__all__ = ["centre_gradient", "law_note"]

# the parameters a stage-1 centre depends on (the runtime's hysteresis_centre)
CENTRE_INPUTS = ("a_h", "b_h", "a_c", "b_c", "cc_share_h", "cc_share_c", "span_ratio_0",
                 "span_ratio_sat", "span_stress")
_STEP = 1e-6            # relative step of the central differences


def centre_gradient(load, direction, params, names):
    """d tau_d / d name [degC per the parameter's unit] of the stage-1 centre at ``load``
    [kg] in ``direction`` (+1/-1) for each of ``names`` (0 for names it does not depend on):
    central differences of the runtime's centre, one-sided for a share on its bound (exact
    for a_d, b_d and cc_share_d, in which the centre is linear)."""
    terms = params.terms
    gradient = np.zeros(len(names))
    centre = hysteresis_centre(load, direction, params)
    for i, name in enumerate(names):
        if name not in CENTRE_INPUTS:
            continue
        value = getattr(params, name)
        value = getattr(terms, name) if value is None else value
        step = _STEP * max(abs(value), 1.0)
        moved, at = [], []
        for sign in (1.0, -1.0):
            try:
                moved.append(hysteresis_centre(load, direction,
                                               params.replace(**{name: value + sign * step})))
                at.append(value + sign * step)
            except ParameterError:
                moved.append(centre)
                at.append(value)
        gradient[i] = (moved[0] - moved[1]) / (at[0] - at[1])
    return gradient


def law_note(option, params, stresses, fitted):
    """{"option", "cc_share_h", "cc_share_c", "note"}: the law asked for and what was done.

    ``stresses``: how many distinct stresses the files hold; ``fitted``: whether the shares
    were unknowns of the fit."""
    terms = params.terms
    if fitted:
        note = (f"centres with a load slope b_d [1 - c_d + c_d s(sigma)/s_sat]: the shares "
                f"c_h = {terms.cc_share_h:.4g}, c_c = {terms.cc_share_c:.4g} fitted from "
                f"{stresses} stresses; b_d is the slope where s has saturated")
    elif option == "clausius-clapeyron" and stresses >= SHARE_STRESSES:
        note = ("centres that follow the transformation strain were not kept: linear centres "
                "(stage_note says why)")
    elif option == "clausius-clapeyron":
        note = (f"the shares of the centres' slopes that follow s(sigma) need "
                f"{SHARE_STRESSES} stresses or more to be fitted; with {stresses} they stay "
                f"from --model (cc_share_h = {terms.cc_share_h!r}, "
                f"cc_share_c = {terms.cc_share_c!r})")
    else:
        note = "centres linear in the load, a_d + b_d f"
    return {"option": option, "cc_share_h": terms.cc_share_h, "cc_share_c": terms.cc_share_c,
            "note": note}
