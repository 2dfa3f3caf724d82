"""How the five FMUs make the closed loop: components, connections, Gauss-Seidel order, outputs.

One description for every place that wires the loop: the loop system (:mod:`.system`: the
fmpy master, the C master, the SSP package, the container FMU) and each FMU's documentation
(:mod:`sma_fmu.fmi.packaging.user_guide`)::

    signals.R_ref --> compensator.R_ref, pi.R_ref        signals.load --> compensator.load, plant.load
    compensator.P_ff --> pi.P_ff     pi.P --> plant.P_in     plant.R --> pi.R

Without the compensator the PI's P_ff input keeps its start (0 W). With a PWM driver between
the PI and the plant (or the same FMU as a linear driver with a current or voltage limit)::

    pi.P --> driver.P_demand     driver.P_in --> plant.P_in

and a driver with a limit reads the wire's resistance::

    plant.R --> driver.R
"""
from dataclasses import dataclass

__all__ = ["Connection", "COMPONENT_MODELS", "STEP_ORDER", "OUTPUTS", "loop_components",
           "loop_connections", "loop_outputs"]

# component name in the system -> its FMU's model name, in data-flow order
COMPONENT_MODELS = {"signals": "SmaScenarioSignals", "compensator": "SmaFeedforward",
                    "pi": "SmaPiController", "driver": "SmaPwmDriver", "plant": "SmaActuator"}

# Gauss-Seidel order of a sequential host: the sampled blocks in data-flow order (the PWM
# driver's output is the wave's mean over the step it was given), then the blocks whose
# outputs hold at the end of their step (plant: the state at t + h; signals: their values
# at t + h), so every block of step k sees R_k, R_ref(t_k), f(t_k) and the u_ff,k, u_k
# and driver power just computed, as in the library loop
STEP_ORDER = ("compensator", "pi", "driver", "plant", "signals")

# a column of the loop's time series -> (component, output variable) it is read from: the
# container FMU's outputs and what every host records
OUTPUTS = {
    "R": ("plant", "R"), "R_ref": ("signals", "R_ref"), "P": ("plant", "P"), "T": ("plant", "T"),
    "load": ("signals", "load"), "x": ("plant", "x"), "xi_P": ("plant", "xi_P"),
    "xi_M": ("plant", "xi_M"), "xi_F": ("plant", "xi_F"), "P_fb": ("pi", "P_fb"),
    "P_ff": ("compensator", "P_ff"), "T_ref": ("compensator", "T_ref"),
    "saturated": ("compensator", "saturated"),
}


@dataclass(frozen=True)
class Connection:
    """``source``.``output`` feeds ``target``.``input`` (component and variable names)."""

    source: str
    output: str
    target: str
    input: str


def loop_components(feedforward, pwm):
    """The loop's component names in data-flow order, with the compensator (``feedforward``)
    and the driver (``pwm``: the SmaPwmDriver FMU, switching or with a limit) or without them."""
    return [name for name in COMPONENT_MODELS
            if (name != "compensator" or feedforward) and (name != "driver" or pwm)]


def loop_connections(feedforward, pwm, limited=False):
    """The loop's :class:`Connection` list, with the compensator (``feedforward``) and the
    driver (``pwm``) or without them; ``limited``: the driver has a current or voltage limit
    and reads the wire's R."""
    power = ([Connection("pi", "P", "driver", "P_demand"), Connection("driver", "P_in", "plant", "P_in")]
             if pwm else [Connection("pi", "P", "plant", "P_in")])
    if pwm and limited:
        power.append(Connection("plant", "R", "driver", "R"))
    connections = [Connection("signals", "R_ref", "pi", "R_ref"), *power,
                   Connection("signals", "load", "plant", "load"),
                   Connection("plant", "R", "pi", "R")]
    if feedforward:
        connections[1:1] = [Connection("signals", "R_ref", "compensator", "R_ref"),
                            Connection("signals", "load", "compensator", "load"),
                            Connection("compensator", "P_ff", "pi", "P_ff")]
    return connections


def loop_outputs(feedforward):
    """The :data:`OUTPUTS` of the loop with the compensator (``feedforward``) or without it
    (the "pi" controller: no P_ff, T_ref, saturated)."""
    return {name: source for name, source in OUTPUTS.items()
            if feedforward or source[0] != "compensator"}
