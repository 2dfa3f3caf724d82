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

Both families read it alike (the C family: c_family/core/layer_start_values.c, same checks,
same order, same messages, all naming the file): it must be a regular file (a FIFO, a
folder or a device is refused at once, never read), of at most :data:`MAX_BYTES`, without a
NUL byte, strict UTF-8 (no encoded surrogates), nested at most :data:`MAX_DEPTH` deep, with
at most :data:`MAX_MEMBERS` distinct keys per object, and JSON as ``json.loads`` reads it.
"""
import json
import math
import os
import re
import stat
from itertools import accumulate

__all__ = ["START_VALUES_FILE", "MAX_BYTES", "MAX_DEPTH", "MAX_MEMBERS", "read_start_values",
           "start_value", "start_value_text", "parse_start_value"]

START_VALUES_FILE = "start_values.json"
# choices, the C family's JSON reader's (runtime/json_text.h): generous for a document of
# some 40 parameters, and bounded so that no file can exhaust the reader
MAX_BYTES = 8 << 20
MAX_DEPTH = 64
MAX_MEMBERS = 256
# a string (to its closing quote, or to the end) or a bracket: what the depth scan counts
_TOKEN = re.compile(rb'"(?:[^"\\]|\\.)*"?|[\[\]{}]', re.S)
_DEPTH = {ord("["): 1, ord("{"): 1, ord("]"): -1, ord("}"): -1, ord('"'): 0}


def start_value(kind, value, name="value"):
    """``value`` as the Python value of an FMI ``kind`` ("Real", "Integer", "Boolean",
    "String") variable; ``ValueError`` naming ``name`` when it is not one."""
    if kind == "Real" and isinstance(value, (int, float)) and not isinstance(value, bool):
        try:
            number = float(value)
        except OverflowError:  # an int too large for a double: refused, as in C
            number = math.inf
        if math.isfinite(number):
            return number
    elif kind == "Integer" and isinstance(value, int) and not isinstance(value, bool):
        if -2 ** 31 <= value < 2 ** 31:
            return value
    elif kind == "Boolean" and isinstance(value, bool):
        return value
    elif kind == "String" and isinstance(value, str):
        return value
    shown = repr(value)[:199]  # as the C family shows it (json_value_repr into 200 bytes)
    raise ValueError(f"{name} = {shown} is not a valid {kind} start value")


def start_value_text(kind, value):
    """The modelDescription.xml / SSP attribute text of a ``kind`` value (a Real NaN, an
    optional wire parameter not given, as XML Schema spells it: ``NaN``)."""
    if kind == "Boolean":
        return "true" if value else "false"
    if kind == "Real":
        return "NaN" if math.isnan(value) else repr(float(value))
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


def _file_bytes(path):
    """The bytes of the regular file ``path``, None if there is none; ``ValueError`` naming it
    when it is not a regular file or is too large. Its type is checked before it is opened
    (Windows cannot open a folder) and again on the descriptor, opened without blocking: a
    FIFO never hangs the instantiation."""
    def refuse(reason):
        return ValueError(f"{path}: cannot be read ({reason})")
    too_large = f"larger than {MAX_BYTES} bytes, the limit for {START_VALUES_FILE}"
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):
            raise refuse("not a regular file")
        flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0)
        descriptor = os.open(path, flags)
    except FileNotFoundError:
        return None
    except OSError as error:
        raise refuse(error.strerror) from None
    try:
        info = os.fstat(descriptor)
        if not stat.S_ISREG(info.st_mode):
            raise refuse("not a regular file")
        if info.st_size > MAX_BYTES:
            raise refuse(too_large)
        chunks = []
        while sum(map(len, chunks)) <= MAX_BYTES:
            chunk = os.read(descriptor, 1 << 20)
            if not chunk:
                break
            chunks.append(chunk)
    except OSError as error:
        raise refuse(error.strerror) from None
    finally:
        os.close(descriptor)
    data = b"".join(chunks)
    if len(data) > MAX_BYTES:
        raise refuse(too_large)
    return data


def _members_hook(pairs):
    """json's object_pairs_hook: a dict, refusing an object of over MAX_MEMBERS distinct keys
    (counted as the C reader counts them: a key beyond the limit is refused, repeated or not)."""
    found = {}
    for key, value in pairs:
        if len(found) >= MAX_MEMBERS:
            raise ValueError(f"an object has more than {MAX_MEMBERS} members")
        found[key] = value
    return found


def _document(path, data):
    """The JSON document in ``data`` (checked in the C family's order); ``ValueError``."""
    def refuse(reason):
        return ValueError(f"{path}: cannot be read ({reason})")
    nul = data.find(b"\0")
    if nul >= 0:
        raise refuse(f"a NUL byte at byte {nul}")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise refuse(f"invalid UTF-8 at byte {error.start}") from None
    steps = (_DEPTH.get(token[0], 0) for token in _TOKEN.findall(data))
    if max(accumulate(steps), default=0) > MAX_DEPTH:
        raise refuse(f"nesting deeper than {MAX_DEPTH} levels, the limit for {START_VALUES_FILE}")
    try:
        return json.loads(text, object_pairs_hook=_members_hook)
    except (ValueError, RecursionError) as error:
        raise refuse(error) from None


def read_start_values(resources):
    """{name: value} of ``<resources>/start_values.json``; {} when the FMU has no such file.

    ``ValueError`` naming the file when it is not such a document.
    """
    path = os.path.join(resources, START_VALUES_FILE)
    data = _file_bytes(path)
    if data is None:
        return {}
    document = _document(path, data)
    values = document.get("values") if isinstance(document, dict) else None
    if not isinstance(values, dict):
        raise ValueError(f"{path}: must be a JSON object with an object 'values'")
    return values
