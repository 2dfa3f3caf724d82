"""Constant-temperature model: load-driven transformation with the M->F ratchet (spec section 7).

    phi(f, T) = 1 / (1 + exp(nu_f (eps_f - g f x_f / N) / (k_B T_K)))
    Phi       = running maximum of phi over the load history      (M -> F is irreversible)
    xi_M = xi_M0 (1 - Phi),   xi_P = xi_P0 (1 - phi)  (P <-> F reversible),   xi_F = 1 - xi_P - xi_M
"""
from .checks import direction_sign, require_nonnegative
from .constant_load import constant_load_fractions, logistic_split, require_temperature
from .constants import BOLTZMANN, COOLING, KELVIN_OFFSET, STANDARD_GRAVITY
from .phases import PhaseFractions, resistance_of

__all__ = ["loading_fraction", "ConstantTemperatureModel"]


def loading_fraction(load, temperature, params):
    """phi(f, T) [1]: how far ``load`` [kg] has driven the M/P -> F transformation at T [degC]."""
    load = require_nonnegative("load", load)
    temperature = require_temperature("temperature", temperature)
    exponent = params.nu_f * (
        params.eps_f - STANDARD_GRAVITY * load * params.x_f / params.N
    ) / (BOLTZMANN * (temperature + KELVIN_OFFSET))
    return logistic_split(1.0, exponent)[0]


class ConstantTemperatureModel:
    """A wire held at one temperature while its load changes (the experiment of paper Fig. 6).

    Parameters
    ----------
    temperature : float
        Wire temperature [degC].
    params : WireParameters
    start : PhaseFractions, optional
        Fractions before any load at this temperature. Default: the constant-load
        state at this temperature with no load, on the ``start_direction`` branch.
    start_direction : "heating" | "cooling"
        Branch of the default start state; "cooling" (the wire was cooled to T).
    """

    def __init__(self, temperature, params, start=None, start_direction=COOLING):
        self.temperature = require_temperature("temperature", temperature)
        self.params = params
        if start is None:
            start = constant_load_fractions(
                self.temperature, 0.0, direction_sign(start_direction), params)
        self.start = PhaseFractions(*start)
        self.max_loading = None  # Phi, the running maximum of phi; None before any load

    def apply_load(self, load):
        """Apply ``load`` [kg]; returns the new :class:`PhaseFractions`."""
        phi = loading_fraction(load, self.temperature, self.params)
        if self.max_loading is None or phi > self.max_loading:
            self.max_loading = phi
        xi_m = self.start.xi_M * (1.0 - self.max_loading)
        xi_p = self.start.xi_P * (1.0 - phi)
        return PhaseFractions(xi_p, xi_m, 1.0 - xi_p - xi_m)

    def resistance_sequence(self, loads):
        """Resistances [ohm] after applying each load [kg] of ``loads`` in order."""
        return [resistance_of(self.apply_load(load), self.params) for load in loads]
