"""How the five FMUs make the closed loop: components, connections, Gauss-Seidel order.

One description for every place that wires the loop: the systems (SSP package, container
FMU, hosts: :mod:`sma_fmu.systems.closed_loop`) and each FMU's documentation
(:mod:`.user_guide`)::

    signals.R_ref --> compensator.R_ref, pi.R_ref        signals.load --> compensator.load, plant.load
    compensator.P_ff --> pi.P_ff     pi.P --> plant.P_in     plant.R --> pi.R

Without the compensator the PI's P_ff input keeps its start (0 W). With a PWM driver between
the PI and the plant::

    pi.P --> driver.P_demand     driver.P_in --> plant.P_in
"""
from dataclasses import dataclass

__all__ = ["Connection", "COMPONENT_MODELS", "STEP_ORDER", "loop_connections"]

# component name in the system -> its FMU's model name
COMPONENT_MODELS = {"signals": "SmaScenarioSignals", "compensator": "SmaFeedforward",
                    "pi": "SmaPiController", "driver": "SmaPwmDriver", "plant": "SmaActuator"}

# Gauss-Seidel order of a sequential host: the sampled blocks in data-flow order (the PWM
# driver's output is the wave's mean over the step it was given), then the blocks whose
# outputs hold at the end of their step (plant: the state at t + h; signals: their values
# at t + h), so every block of step k sees R_k, R_ref(t_k), f(t_k) and the u_ff,k, u_k
# and driver power just computed, as in the library loop
STEP_ORDER = ("compensator", "pi", "driver", "plant", "signals")


@dataclass(frozen=True)
class Connection:
    """``source``.``output`` feeds ``target``.``input`` (component and variable names)."""

    source: str
    output: str
    target: str
    input: str


def loop_connections(feedforward, pwm):
    """The loop's :class:`Connection` list, with the compensator (``feedforward``) and the PWM
    driver (``pwm``) or without them."""
    power = ([Connection("pi", "P", "driver", "P_demand"), Connection("driver", "P_in", "plant", "P_in")]
             if pwm else [Connection("pi", "P", "plant", "P_in")])
    connections = [Connection("signals", "R_ref", "pi", "R_ref"), *power,
                   Connection("signals", "load", "plant", "load"),
                   Connection("plant", "R", "pi", "R")]
    if feedforward:
        connections[1:1] = [Connection("signals", "R_ref", "compensator", "R_ref"),
                            Connection("signals", "load", "compensator", "load"),
                            Connection("compensator", "P_ff", "pi", "P_ff")]
    return connections
