"""Input signals shared by the FMU tests (plain functions of the step index)."""
import math

STEP = 1e-3  # s


def plant_power(k):
    """Power [W] that heats into the transformation and oscillates there (reversals)."""
    t = k * STEP
    return max(0.0, 1.9 + 0.9 * math.sin(2.0 * math.pi * 0.5 * t) - 0.4 * math.exp(-t))


def plant_load(k):
    """Load [kg] stepping 3.2e-3 -> 0.05 -> 0.15 like the paper's load-step scenario."""
    t = k * STEP
    return 3.2e-3 if t < 3.0 else (0.05 if t < 6.0 else 0.15)


def reference(k):
    """The paper's reference R_ref(t) = 41.85 + 6.05 cos(2 pi 0.5 t) [ohm]."""
    return 41.85 + 6.05 * math.cos(2.0 * math.pi * 0.5 * k * STEP)


def wide_reference(k):
    """A reference [ohm] reaching past both saturated ends (32.4 ... 51.4 ohm)."""
    return 41.85 + 9.5 * math.cos(2.0 * math.pi * 0.5 * k * STEP)
