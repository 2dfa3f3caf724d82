"""The wire model's validity range: warnings when the temperature or the load leaves it.

``validity.T_max`` [degC] and the load limit ``load_max`` [kg] (from ``validity.stress_max``
[MPa] and the wire's diameter) bound where the parameters were identified. Above them the
model still computes, and a stepper says so once per excursion: in the step (or the start)
in which a value rises past its limit. The FMUs log the message as fmi2Warning.

A wire fitted to data also gives the range those data covered (``validity.T_data_min`` ...
``stress_data_max``, optional): a run that leaves it is extrapolating the fit, and a stepper
says so once, the first time (:func:`data_range_warning`); the model still computes.
"""
import math

__all__ = ["validity_warning", "data_range_warning", "data_box", "DATA_RANGE_NOTE"]

DATA_RANGE_NOTE = ("outside the range of the data the wire's parameters were fitted to "
                   "(warned once per instance)")


def validity_warning(params, temperature, temperature_before, load, load_before):
    """The warning [str] for a step that took T [degC] / load [kg] above their limits from
    at or below them, or None."""
    messages = []
    if temperature > params.T_max >= temperature_before:
        messages.append(f"T = {temperature:.6g} degC rose above validity.T_max = "
                        f"{params.T_max:g} degC")
    if load > params.load_max >= load_before:
        messages.append(f"load = {load:.6g} kg rose above the validity limit {params.load_max:.4g} kg "
                        f"(validity.stress_max = {params.stress_max:g} MPa on a "
                        f"{params.diameter * 1e3:g} mm wire)")
    if not messages:
        return None
    return "; ".join(messages) + ": outside the range the model's parameters describe"


def data_box(params):
    """(T_data_min, T_data_max [degC], load_data_min, load_data_max [kg]) of ``params``, a
    bound not given as -inf or inf: a stepper compares with these at every step until it has
    warned, and calls :func:`data_range_warning` only for a value outside (the call inside
    the range cost ~0.1 us a step in Python)."""
    def bound(value, missing):
        return missing if value is None else value
    return (bound(params.T_data_min, -math.inf), bound(params.T_data_max, math.inf),
            bound(params.load_data_min, -math.inf), bound(params.load_data_max, math.inf))


def data_range_warning(params, temperature, load, name="T"):
    """The warning [str] when the temperature ``name`` [degC] or the load [kg] lies outside
    the data range of ``params`` (its T_data_min ... stress_data_max; a bound not given does
    not apply), or None. The C family writes the same text. Inside the range it returns after
    the comparisons alone: a stepper asks at every step until it has warned."""
    low, high = params.T_data_min, params.T_data_max
    load_low, load_high = params.load_data_min, params.load_data_max
    if ((low is None or temperature >= low) and (high is None or temperature <= high)
            and (load_low is None or load >= load_low)
            and (load_high is None or load <= load_high)):
        return None
    messages = []
    if params.T_data_min is not None and temperature < params.T_data_min:
        messages.append(f"{name} = {temperature:.6g} degC is below validity.T_data_min = "
                        f"{params.T_data_min:g} degC")
    if params.T_data_max is not None and temperature > params.T_data_max:
        messages.append(f"{name} = {temperature:.6g} degC is above validity.T_data_max = "
                        f"{params.T_data_max:g} degC")
    wire = f"on a {params.diameter * 1e3:g} mm wire"
    if params.load_data_min is not None and load < params.load_data_min:
        messages.append(f"load = {load:.6g} kg is below {params.load_data_min:.4g} kg "
                        f"(validity.stress_data_min = {params.stress_data_min:g} MPa {wire})")
    if params.load_data_max is not None and load > params.load_data_max:
        messages.append(f"load = {load:.6g} kg is above {params.load_data_max:.4g} kg "
                        f"(validity.stress_data_max = {params.stress_data_max:g} MPa {wire})")
    if not messages:
        return None
    return "; ".join(messages) + ": " + DATA_RANGE_NOTE
