"""What pythonfmu 0.7.0 leaves out of modelDescription.xml, added with xml.etree (stdlib only).

- ``<UnitDefinitions>`` and a ``unit`` attribute on every Real variable that has one;
- ``ModelStructure/Outputs`` dependencies (empty: outputs change only in doStep);
- ``ModelStructure/InitialUnknowns`` listing the outputs computed at initialization;
- Real ``start`` values that read back exactly: pythonfmu writes ``f"{start:.16g}"``, and a
  double can need 17 significant digits (a fitted a_h of 59.713553341652535 came
  back from the FMU as 59.71355334165253, one unit in the last place away).
"""
from xml.etree.ElementTree import Element, SubElement

from .start_values import start_value_text

__all__ = ["UNIT_DEFINITIONS", "set_units", "set_exact_starts", "decorate_model_description"]

# FMI 2.0 BaseUnit exponents (kg, m, s, A, K) and offset for every unit the FMUs use
UNIT_DEFINITIONS = {
    "1": {},
    "W": {"kg": 1, "m": 2, "s": -3},
    "kg": {"kg": 1},
    "ohm": {"kg": 1, "m": 2, "s": -3, "A": -2},
    "degC": {"K": 1, "offset": 273.15},
    "m": {"m": 1},
    "s": {"s": 1},
    "Hz": {"s": -1},
    "degC/kg": {"K": 1, "kg": -1},
    "J": {"kg": 1, "m": 2, "s": -2},
    "m2": {"m": 2},
    "J/(kg.K)": {"m": 2, "s": -2, "K": -1},
    "W/(m2.K)": {"kg": 1, "s": -3, "K": -1},
    "W/ohm": {"A": 2},
    "W/(ohm.s)": {"A": 2, "s": -1},
    "MPa": {"kg": 1, "m": -1, "s": -2, "factor": 1e6},
    "1/K": {"K": -1},
    "A": {"A": 1},
    "V": {"kg": 1, "m": 2, "s": -3, "A": -1},
}

# schema order of fmiModelDescription's children (FMI 2.0 XSD)
_ORDER = ["CoSimulation", "UnitDefinitions", "TypeDefinitions", "LogCategories",
          "DefaultExperiment", "VendorAnnotations", "ModelVariables", "ModelStructure"]


def _unit_definitions(units):
    node = Element("UnitDefinitions")
    for name in sorted(set(units)):
        if name not in UNIT_DEFINITIONS:
            raise ValueError(f"unit {name!r} has no FMI definition; add it to UNIT_DEFINITIONS")
        unit = SubElement(node, "Unit", name=name)
        SubElement(unit, "BaseUnit", {k: str(v) for k, v in UNIT_DEFINITIONS[name].items()})
    return node


def set_units(root, units):
    """Set ``unit`` on each Real variable of the model description ``root`` named in
    ``units`` (variable name -> a key of :data:`UNIT_DEFINITIONS`), add their
    ``<UnitDefinitions>`` in schema order; returns ``root``, changed in place."""
    for variable in root.find("ModelVariables"):
        real = variable.find("Real")
        if real is not None and variable.get("name") in units:
            real.set("unit", units[variable.get("name")])
    if units:
        root.insert(_ORDER.index("UnitDefinitions"), _unit_definitions(units.values()))
        children = sorted(root, key=lambda child: _ORDER.index(child.tag))
        for child in list(root):
            root.remove(child)
        root.extend(children)
    return root


def set_exact_starts(root, starts):
    """Rewrite the ``start`` of each Real variable of ``root`` named in ``starts`` (variable
    name -> float) whose text does not read back as that value, as ``repr``; returns ``root``.
    (Texts that do, like pythonfmu's ``0`` for 0.0, stay as they are.)"""
    for variable in root.find("ModelVariables"):
        real, name = variable.find("Real"), variable.get("name")
        if real is not None and real.get("start") is not None and name in starts \
                and float(real.get("start")) != float(starts[name]):
            real.set("start", start_value_text("Real", starts[name]))
    return root


def decorate_model_description(root, units, starts=None):
    """Complete pythonfmu's ``root`` element in place and return it.

    ``units`` maps variable names to unit names (keys of :data:`UNIT_DEFINITIONS`);
    ``starts`` maps Real variable names to the start values pythonfmu wrote rounded.
    """
    set_units(root, units)
    set_exact_starts(root, starts or {})
    output_indices = [index for index, variable in enumerate(root.find("ModelVariables"), start=1)
                      if variable.get("causality") == "output"
                      and variable.get("initial") in ("calculated", "approx")]
    structure = root.find("ModelStructure")
    outputs = structure.find("Outputs")
    if outputs is not None:
        for unknown in outputs:
            unknown.set("dependencies", "")
    if output_indices:
        initial = SubElement(structure, "InitialUnknowns")
        for index in output_indices:
            SubElement(initial, "Unknown", index=str(index))
    return root
