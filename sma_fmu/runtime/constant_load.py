"""Constant-load model with a direction-switched hysteresis centre (spec sections 3-4).

    tau(f, d)  = a_h + b_h f (heating), a_c + b_c f (cooling)        [degC]
                 (cc_share_d > 0: f_d of model_terms.centre_load in place of f)
    xi_Fmin(f) = xi_F_inf (1 - exp(-f/f_F))                           residual F when hot
    dH(f)      = nu (eps_T - g f x_T / N)                             [J] per cooperative domain
    Lambda     = ln(xi_P/xi_MF) = (dH/k_B)(1/tau_K - 1/T_K)
    xi_MF      = M/(1 + e^Lambda),  xi_P = M - xi_MF,  M = 1 - xi_Fmin
    xi_M = xi_MF/2,  xi_F = xi_Fmin + xi_MF/2

With the optional model terms (:mod:`.model_terms`) dH uses nu_d of the direction, and
with a second stage (w2 > 0) the major branch is a weighted sum of two logistics,

    xi_MF = M (1 - w2)/(1 + e^Lambda1) + M w2/(1 + e^Lambda2),   Lambda2 with nu2_d, a2_d + b2_d f

each half split as :func:`logistic_split` does (xi_P from the other half, for digits).

The load-dependent constants of one branch are bundled in :class:`BranchConstants`
so a stepper computes them once per load, not once per step.
"""
import math
from collections import namedtuple

from .checks import direction_sign, require_finite, require_nonnegative
from .constants import BOLTZMANN, HEATING, KELVIN_OFFSET, STANDARD_GRAVITY
from .model_terms import centre_load, length_constants, stressed_lengths
from .phases import PhaseFractions, resistance_of

_exp = math.exp

__all__ = [
    "BranchConstants", "slope_load", "hysteresis_centre", "second_centre", "residual_f_fraction",
    "domain_energy", "branch_constants", "logistic_split", "branch_fractions",
    "two_stage_fractions", "with_second_stage", "phase_fractions",
    "constant_load_fractions", "constant_load_resistance", "require_temperature", "BranchCache",
]

BranchConstants = namedtuple(
    "BranchConstants", ["M", "xi_F_min", "energy_over_kB", "inv_centre_K", "centre",
                        "w2", "M1", "M2", "energy2_over_kB", "inv_centre2_K", "centre2",
                        "length_M", "length_F", "stages", "strain"],
    defaults=(0.0, None, None, None, None, None, None, None, None, None))
BranchConstants.__doc__ = """Constants of one major branch at one load.

M : 1 - xi_Fmin, the fraction that can transform [1]
xi_F_min : residual F fraction [1]
energy_over_kB : dH(f)/k_B [K]
inv_centre_K : 1/tau_K [1/K]
centre : hysteresis centre tau [degC]
w2 : share of M in the second stage [1] (0: one stage; the rest of the fields are then None)
M1, M2 : M (1 - w2) and M w2 [1]; energy2_over_kB [K], inv_centre2_K [1/K], centre2 [degC]:
    the second stage's dH/k_B, 1/tau2_K and tau2
length_M, length_F : l_M and l_F at this load and T_alpha [m] (None without strain terms)
stages : (M1, energy_over_kB, inv_centre_K, M2, energy2_over_kB, inv_centre2_K) of a second
    stage (:func:`with_second_stage`), one tuple for the per-step paths (a field lookup costs
    what a short operation does in Python); None for one stage
strain : the strain terms' length constants of :func:`~.model_terms.length_of` (None without)
"""


def require_temperature(name, value):
    """Return ``value`` [degC] as float if finite and above absolute zero, else raise."""
    temperature = require_finite(name, value)
    if temperature <= -KELVIN_OFFSET:
        raise ValueError(f"{name} must be above -273.15 degC, got {value!r}")
    return temperature


def slope_load(load, direction, params):
    """The load [kg] the centres' slopes multiply in ``direction``: ``load`` itself, or with
    cc_share_d > 0 the strain-weighted load of :func:`~.model_terms.centre_load`."""
    terms = params.terms
    share = terms.cc_share_h if direction_sign(direction) == HEATING else terms.cc_share_c
    return load if share == 0.0 else centre_load(load, share, terms)


def hysteresis_centre(load, direction, params):
    """Hysteresis centre tau [degC] for a load [kg] and direction (+1 heating, -1 cooling):
    a_d + b_d f (the strain-weighted load with cc_share_d > 0: :func:`slope_load`)."""
    load = slope_load(load, direction, params)
    if direction_sign(direction) == HEATING:
        return params.a_h + params.b_h * load
    return params.a_c + params.b_c * load


def second_centre(load, direction, params):
    """Second-stage centre tau2 [degC] = a2_d + b2_d f for a load [kg] and direction (the
    strain-weighted load with cc_share_d > 0, as :func:`hysteresis_centre`)."""
    terms = params.terms
    load = slope_load(load, direction, params)
    if direction_sign(direction) == HEATING:
        return terms.a2_h + terms.b2_h * load
    return terms.a2_c + terms.b2_c * load


def _checked_centre(centre, load, what):
    """``centre`` [degC], refused when not finite or at or below 0 K; ``what`` names it and
    the parameters it is made of (e.g. "hysteresis centre a_h + b_h f")."""
    if not centre < math.inf:
        raise ValueError(f"load = {load!r} kg is beyond the model's range: the {what} = "
                         f"{centre!r} degC is not finite")
    if centre <= -KELVIN_OFFSET:
        raise ValueError(f"{what} = {centre!r} degC at load {load!r} kg is below 0 K")
    return centre


def residual_f_fraction(load, params):
    """Residual F fraction xi_Fmin(f) [1] left when the wire under ``load`` [kg] is fully heated."""
    return params.xi_F_inf * (1.0 - math.exp(-load / params.f_F))


def domain_energy(load, params, nu=None):
    """Transformation energy per cooperative domain dH(f) [J]; must stay positive.

    ``nu`` [1]: the domain size (default ``params.nu``; nu_h, nu_c, nu2_d for the terms)."""
    nu = params.nu if nu is None else nu
    energy = nu * (params.eps_T - STANDARD_GRAVITY * load * params.x_T / params.N)
    if not energy < math.inf or not energy / BOLTZMANN < math.inf:
        raise ValueError(f"load = {load!r} kg is beyond the model's range: dH(f) overflows")
    if not energy > 0.0:
        raise ValueError(
            f"load = {load!r} kg is beyond the model's range: dH(f) = {energy!r} J <= 0")
    return energy


def branch_constants(load, direction, params):
    """The :class:`BranchConstants` of the major branch for ``load`` [kg] and ``direction``."""
    load = require_nonnegative("load", load)
    heating = direction_sign(direction) == HEATING
    terms = params.terms
    centre = _checked_centre(hysteresis_centre(load, direction, params), load,
                             "hysteresis centre a_h + b_h f" if heating
                             else "hysteresis centre a_c + b_c f")
    xi_f_min = residual_f_fraction(load, params)
    total = 1.0 - xi_f_min
    constants = BranchConstants(
        M=total,
        xi_F_min=xi_f_min,
        energy_over_kB=domain_energy(load, params, terms.nu_h if heating else terms.nu_c)
        / BOLTZMANN,
        inv_centre_K=1.0 / (centre + KELVIN_OFFSET),
        centre=centre,
    )
    if terms.two_stage:
        centre2 = _checked_centre(second_centre(load, direction, params), load,
                                  "second-stage centre a2_h + b2_h f" if heating
                                  else "second-stage centre a2_c + b2_c f")
        energy2 = domain_energy(load, params, terms.nu2_h if heating else terms.nu2_c)
        constants = with_second_stage(constants, terms.w2, total * (1.0 - terms.w2),
                                      total * terms.w2, energy2 / BOLTZMANN,
                                      1.0 / (centre2 + KELVIN_OFFSET), centre2)
    if terms.strain:
        length_m, length_f = stressed_lengths(load, params)
        constants = constants._replace(length_M=length_m, length_F=length_f,
                                       strain=length_constants(length_m, length_f, params))
    return constants


def with_second_stage(constants, w2, M1, M2, energy2_over_kB, inv_centre2_K, centre2=None):
    """``constants`` (:class:`BranchConstants`) with a second stage: share ``w2`` [1], the
    stages' M1, M2 [1], dH2/k_B [K], 1/tau2_K [1/K] and tau2 [degC], and ``stages``."""
    return constants._replace(
        w2=w2, M1=M1, M2=M2, energy2_over_kB=energy2_over_kB, inv_centre2_K=inv_centre2_K,
        centre2=centre2, stages=(M1, constants.energy_over_kB, constants.inv_centre_K, M2,
                                 energy2_over_kB, inv_centre2_K))


def logistic_split(total, exponent):
    """Split ``total`` into (total/(1+e^z), total e^z/(1+e^z)) without overflow or cancellation."""
    if exponent > 0.0:
        e = math.exp(-exponent)
        return total * e / (1.0 + e), total / (1.0 + e)
    e = math.exp(exponent)
    return total / (1.0 + e), total * e / (1.0 + e)


def branch_fractions(temperature, constants):
    """(xi_MF, xi_P) [1] on a major branch at ``temperature`` [degC] (no argument checks)."""
    if constants.w2 != 0.0:
        return two_stage_fractions(1.0 / (temperature + KELVIN_OFFSET), constants)
    exponent = constants.energy_over_kB * (
        constants.inv_centre_K - 1.0 / (temperature + KELVIN_OFFSET))
    return logistic_split(constants.M, exponent)


def two_stage_fractions(inverse_kelvin, constants):
    """(xi_MF, xi_P) [1] of a two-stage major branch at 1/T_K = ``inverse_kelvin`` [1/K]:
    each stage split by :func:`logistic_split`, the halves added (stage 1 first). The splits
    are written out (the same operations): a plant calls this at every step, and the two
    calls cost a fifth of it in Python."""
    total, energy1, centre1, total2, energy2, centre2 = constants.stages
    exponent = energy1 * (centre1 - inverse_kelvin)
    if exponent > 0.0:
        e = _exp(-exponent)
        d = 1.0 + e
        mf, p = total * e / d, total / d
    else:
        e = _exp(exponent)
        d = 1.0 + e
        mf, p = total / d, total * e / d
    exponent = energy2 * (centre2 - inverse_kelvin)
    if exponent > 0.0:
        e = _exp(-exponent)
        d = 1.0 + e
        return mf + total2 * e / d, p + total2 / d
    e = _exp(exponent)
    d = 1.0 + e
    return mf + total2 / d, p + total2 * e / d


def phase_fractions(xi_mf, xi_p, xi_f_min):
    """PhaseFractions from the mixed fraction xi_MF, xi_P and the residual F (xi_M = xi_F')."""
    half = 0.5 * xi_mf
    return PhaseFractions(xi_p, half, xi_f_min + half)


def constant_load_fractions(temperature, load, direction, params):
    """Phase fractions on the major branch at ``temperature`` [degC], ``load`` [kg], ``direction``."""
    temperature = require_temperature("temperature", temperature)
    constants = branch_constants(load, direction, params)
    xi_mf, xi_p = branch_fractions(temperature, constants)
    return phase_fractions(xi_mf, xi_p, constants.xi_F_min)


def constant_load_resistance(temperature, load, direction, params):
    """Resistance R(T, f, d) [ohm] on the major branch (paper eq. 30)."""
    return resistance_of(constant_load_fractions(temperature, load, direction, params), params)


class BranchCache:
    """Memo of :func:`branch_constants` per (load, direction) for steppers.

    Loads are usually piecewise constant, so a few entries serve a whole run; the memo
    is emptied when it reaches ``size`` entries so a continuously varying load stays cheap.
    """

    def __init__(self, params, size=64):
        self.params = params
        self.size = size
        self._entries = {}
        self._last = (None, None, None)  # (load, direction, constants) of the last call

    def get(self, load, direction):
        """BranchConstants for ``load`` [kg] and ``direction`` (+1/-1)."""
        last_load, last_direction, constants = self._last
        if load == last_load and direction == last_direction:
            return constants
        key = (load, direction)
        constants = self._entries.get(key)
        if constants is None:
            constants = branch_constants(load, direction, self.params)
            if len(self._entries) >= self.size:
                self._entries.clear()
            self._entries[key] = constants
        self._last = (load, direction, constants)
        return constants
