"""Input signals shared by the FMU tests: plain functions of the step index, and the plant's
random walk."""
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


def plant_walk(rng, count):
    """``count`` steps of plant inputs {"P_in" [W], "load" [kg]} drawn from ``rng`` (a
    random.Random): power held for random spans, its swings shrinking then growing again
    (nested reversals), and load changes now and then."""
    inputs, power, load, amplitude = [], 0.0, 0.2, 2.0
    for k in range(count):
        if k % rng.randint(40, 300) == 0:
            amplitude = 2.0 if amplitude < 0.05 else amplitude * rng.uniform(0.5, 0.9)
            power = max(0.0, 1.0 + rng.choice((-1, 1)) * amplitude * rng.random())
        if rng.random() < 0.002:
            load = rng.uniform(0.0, 0.4)
        inputs.append({"P_in": power, "load": load})
    return inputs
