"""The wire model's validity range: warnings when the temperature or the load leaves it.

``validity.T_max`` [degC] and the load limit ``load_max`` [kg] (from ``validity.stress_max``
[MPa] and the wire's diameter) bound where the parameters were identified. Above them the
model still computes, and a stepper says so once per excursion: in the step (or the start)
in which a value rises past its limit. The FMUs log the message as fmi2Warning.
"""
__all__ = ["validity_warning"]


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
