"""``terminalsAndIcons/terminalsAndIcons.xml`` of the FMI 3.0 plant: its physical connections.

A tool that reads FMI 3.0 terminals can then connect the plant by what it is wired to, not
by variable names: an electrical terminal (``P_in`` in, ``R`` out: the drive sets the power,
the sensing reads the resistance), a thermal one (``T``) and a mechanical one (``load`` in,
``x`` out). Each is a ``bus`` of signals (the FMU has no physical flow variables). Models
without these variables get no file.
"""
import xml.etree.ElementTree as ET

__all__ = ["TERMINALS", "terminals_and_icons"]

# terminal name -> (terminalKind, description, [variable names])
TERMINALS = {
    "electrical": ("org.sma-fmu.electrical", "the drive's power into the wire [W] and the "
                   "wire's resistance [ohm]", ["P_in", "R"]),
    "thermal": ("org.sma-fmu.thermal", "the wire's temperature [degC]", ["T"]),
    "mechanical": ("org.sma-fmu.mechanical", "the hung mass [kg] and the wire's length [m]",
                   ["load", "x"]),
}


def terminals_and_icons(fmi3_description_bytes):
    """The file's bytes for the FMU of this FMI 3.0 description, or None if it has none of
    the terminals' variables."""
    names = {v.get("name") for v in ET.fromstring(fmi3_description_bytes).find("ModelVariables")}
    root = ET.Element("fmiTerminalsAndIcons", fmiVersion="3.0")
    terminals = ET.SubElement(root, "Terminals")
    for name, (kind, description, variables) in TERMINALS.items():
        if not set(variables) <= names:
            continue
        terminal = ET.SubElement(terminals, "Terminal", name=name, matchingRule="bus",
                                 terminalKind=kind, description=description)
        for variable in variables:
            ET.SubElement(terminal, "TerminalMemberVariable", variableName=variable,
                          memberName=variable, variableKind="signal")
    if not len(terminals):
        return None
    ET.indent(root, "\t")
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True) + b"\n"
