"""Start values packed into an FMU at export: ``resources/start_values.json`` (standard library only).

``sma-fmu export`` packs each FMU of an SSP or a container with the scenario's parameter
values as the FMU's *defaults*: it writes them into modelDescription.xml (the ``start``
attributes) and into this file, which the slave reads when it is instantiated
(:class:`~.interface.SlaveInterface`). A host that binds no parameter (fmpy's
``simulate_ssp``) or not every type (OMSimulator binds no Strings) then runs the scenario
as well as one that binds them all; the bindings stay, and hold the same values. The file::

    {"source": "sma-fmu export: scenario heavy-pi", "values": {"hysteresis_mode": 2, "Kp": 0.3}}

Values are JSON numbers, booleans and strings, one per parameter name, of the variable's
FMI type (a Real may be written as an integer).
"""
import json
import math
import os

__all__ = ["START_VALUES_FILE", "read_start_values", "start_value", "start_value_text",
           "parse_start_value"]

START_VALUES_FILE = "start_values.json"


def start_value(kind, value, name="value"):
    """``value`` as the Python value of an FMI ``kind`` ("Real", "Integer", "Boolean",
    "String") variable; ``ValueError`` naming ``name`` when it is not one."""
    if kind == "Real" and isinstance(value, (int, float)) and not isinstance(value, bool):
        if math.isfinite(value):
            return float(value)
    elif kind == "Integer" and isinstance(value, int) and not isinstance(value, bool):
        if -2 ** 31 <= value < 2 ** 31:
            return value
    elif kind == "Boolean" and isinstance(value, bool):
        return value
    elif kind == "String" and isinstance(value, str):
        return value
    raise ValueError(f"{name} = {value!r} is not a valid {kind} start value")


def start_value_text(kind, value):
    """The modelDescription.xml / SSP attribute text of a ``kind`` value."""
    if kind == "Boolean":
        return "true" if value else "false"
    if kind == "Real":
        return repr(float(value))
    if kind == "Integer":
        return str(int(value))
    return str(value)


def parse_start_value(kind, text):
    """The value of a modelDescription.xml / SSP attribute ``text`` of type ``kind``."""
    if kind == "Boolean":
        if text not in ("true", "false", "1", "0"):
            raise ValueError(f"{text!r} is not a Boolean")
        return text in ("true", "1")
    if kind == "Real":
        return float(text)
    if kind == "Integer":
        return int(text)
    return text


def read_start_values(resources):
    """{name: value} of ``<resources>/start_values.json``; {} when the FMU has no such file.

    ``ValueError`` naming the file when it is not such a document.
    """
    path = os.path.join(resources, START_VALUES_FILE)
    if not os.path.isfile(path):
        return {}
    try:
        with open(path, encoding="utf-8") as stream:
            document = json.load(stream)
    except (OSError, ValueError) as error:
        raise ValueError(f"{path}: cannot be read ({error})") from None
    values = document.get("values") if isinstance(document, dict) else None
    if not isinstance(values, dict):
        raise ValueError(f"{path}: must be a JSON object with an object 'values'")
    return values
