"""Wire values that follow from its geometry: the surface area and the mass.

A parameter file may give, instead of ``thermal.A_s`` and ``geometry.mass``:
- nothing for A_s: it is the lateral surface pi d x0 of the wire [m2] (the ends, pi d^2/2,
  are below 0.02 % of it for any wire thinner than 0.3 mm and longer than 0.5 m);
- ``geometry.density`` [kg/m3] (mass = density * pi d^2/4 * x0) or
  ``geometry.linear_density`` [kg/m] (mass = linear_density * x0) for the mass.
An explicit value wins. Where the mass is given more than one way, the ways must agree
within :data:`AGREEMENT`; a contradiction is an error naming both keys.
"""
import math

from sma_fmu.runtime.parameters import (ParameterError, ParameterSpec, requirement_text,
                                        value_in_range)

__all__ = ["GEOMETRY_INPUTS", "AGREEMENT", "complete_from_geometry"]

GEOMETRY_INPUTS = (
    # kg/m3: Ti-Ni 6450, NiTiHf about 8000+; the densest element (osmium) is 22,600
    ParameterSpec("density", "geometry", "kg/m3", "positive", False, (0.0, 3e4)),
    # kg/m: a 10 mm NiTiHf rod is 0.7 kg/m
    ParameterSpec("linear_density", "geometry", "kg/m", "positive", False, (0.0, 1.0)),
)
AGREEMENT = 1e-3  # relative difference allowed between two ways of giving the mass
DERIVABLE = ("A_s", "mass")


def _masses(values):
    """{key: (value, mass it implies [kg])} for every way the file gives the mass."""
    x0, diameter = values.get("x0"), values.get("diameter")
    ways = {}
    if "mass" in values:
        ways["geometry.mass"] = (values["mass"], values["mass"])
    if "density" in values and x0 is not None and diameter is not None:
        ways["geometry.density"] = (values["density"],
                                    values["density"] * math.pi * diameter ** 2 / 4.0 * x0)
    if "linear_density" in values and x0 is not None:
        ways["geometry.linear_density"] = (values["linear_density"], values["linear_density"] * x0)
    return ways


def complete_from_geometry(values, source):
    """Fill in A_s and mass from the geometry where the file leaves them out.

    ``values`` maps parameter names (including ``density`` and ``linear_density``) to
    numbers. Returns (the values without the geometry-only keys, {derived name: how}).
    """
    values = dict(values)
    derived = {}
    for spec in GEOMETRY_INPUTS:
        if spec.name in values and not value_in_range(spec, values[spec.name]):
            raise ParameterError(f"{source}: parameter {spec.section}.{spec.name} = "
                                 f"{values[spec.name]!r} must be "
                                 f"{requirement_text(spec, values[spec.name])} [{spec.unit}]")
    ways = _masses(values)
    keys = list(ways)
    for i, first in enumerate(keys):
        for second in keys[i + 1:]:
            a, b = ways[first][1], ways[second][1]
            if abs(a - b) > AGREEMENT * max(abs(a), abs(b)):
                raise ParameterError(
                    f"{source}: {first} = {ways[first][0]!r} and {second} = {ways[second][0]!r} "
                    f"contradict each other: they give a mass of {a:.6g} kg and {b:.6g} kg "
                    f"(they must agree within {AGREEMENT:.1%}); give one of them")
    if "mass" not in values:
        if not ways:
            raise ParameterError(f"{source}: missing parameter geometry.mass: give mass [kg], "
                                 f"density [kg/m3] or linear_density [kg/m]")
        key = keys[0]
        values["mass"] = ways[key][1]
        formula = ("density * pi diameter^2/4 * x0" if key.endswith(".density")
                   else "linear_density * x0")
        derived["mass"] = f"{formula} = {values['mass']:.6g} kg (from {key})"
    if "A_s" not in values and "diameter" in values and "x0" in values:
        values["A_s"] = math.pi * values["diameter"] * values["x0"]
        derived["A_s"] = f"pi * diameter * x0 = {values['A_s']:.6g} m2 (lateral surface)"
    for spec in GEOMETRY_INPUTS:
        values.pop(spec.name, None)
    return values, derived
