"""First-order thermal model of the Joule-heated wire (spec section 9, paper eqs. 43-44).

    m cp dT/dt = u - hc As (T - Troom),   G_th(s) = K_th / (tau_th s + 1)
"""
import math

__all__ = ["thermal_gain", "thermal_time_constant", "step_decay", "thermal_step", "power_to_reach"]


def thermal_gain(h_c, A_s):
    """Static gain K_th = 1/(hc As) [K/W] from convection coefficient [W/(m2.K)] and area [m2]."""
    return 1.0 / (h_c * A_s)


def thermal_time_constant(mass, c_p, h_c, A_s):
    """Time constant tau_th = m cp/(hc As) [s] from mass [kg] and specific heat [J/(kg.K)]."""
    return mass * c_p / (h_c * A_s)


def step_decay(step_size, time_constant):
    """Zero-order-hold decay factor exp(-h/tau_th) [1] for a step h [s]."""
    return math.exp(-step_size / time_constant)


def thermal_step(temperature, power, T_room, gain, decay):
    """Exact temperature [degC] after one step with the power held.

    T+ = Troom + (T - Troom) e^(-h/tau) + K_th u (1 - e^(-h/tau)),
    with temperature and T_room in degC, power u in W, gain K_th in K/W and
    ``decay`` = e^(-h/tau) from :func:`step_decay`.
    """
    return T_room + (temperature - T_room) * decay + gain * power * (1.0 - decay)


def power_to_reach(temperature, target, T_room, gain, decay):
    """The power u [W] that takes the thermal model from ``temperature`` to ``target`` [degC].

    Inverts :func:`thermal_step`,
    T+ = T_room + (T - T_room) e^(-h/tau) + K_th u (1 - e^(-h/tau)), for u, with
    ``T_room`` [degC], ``gain`` K_th [K/W] and ``decay`` e^(-h/tau) [1] < 1. A negative
    result means the target lies below where passive cooling gets in that step.
    """
    return (target - T_room - (temperature - T_room) * decay) / (gain * (1.0 - decay))
