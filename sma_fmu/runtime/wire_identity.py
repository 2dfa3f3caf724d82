"""A wire's identity: the SHA-256 digest of its canonical values (standard library only).

The canonical text of a parameter set (:func:`canonical_text`) is the line ``sma-fmu wire 1``,
then one line ``name=value`` per parameter the set holds (``WireParameters.values()``: every
parameter of the schema but the optional ones it does not give), sorted by name (ASCII),
each value written as Python's ``repr`` of the float (the shortest text that reads back as
the same double; ``memory_depth`` too: 64 is ``64.0``), every line ending in a newline.
The digest (:func:`wire_digest`) is ``"sha256:"`` and the 64 lowercase hex digits of the
SHA-256 of that text in UTF-8.

So it depends on the validated values alone: not on a file's comments, meanings, name,
description, order of entries or number formatting (``0.15e-3`` and ``1.5e-4`` are one
value), nor on which geometry inputs derived a value. One unit in the last place of any
value changes it; so does giving an optional parameter the file omitted, even at the value
the model takes in its place (the file then says something else). Every FMU states the
digest of the wire it was built from; runs record the digest of the wire they ran.
"""
import hashlib

__all__ = ["CANONICAL_HEADER", "DIGEST_PREFIX", "canonical_text", "wire_digest",
           "digest_of_values", "is_digest"]

CANONICAL_HEADER = "sma-fmu wire 1"
DIGEST_PREFIX = "sha256:"
_HEX = frozenset("0123456789abcdef")


def _canonical(values):
    lines = [CANONICAL_HEADER]
    lines += [f"{name}={float(values[name])!r}" for name in sorted(values)
              if values[name] is not None]
    return "\n".join(lines) + "\n"


def canonical_text(params):
    """The canonical text of ``params`` (a :class:`~.parameters.WireParameters`)."""
    return _canonical(params.values())


def digest_of_values(values):
    """The digest of ``values`` ({name: number or None}, None: not given), validated already."""
    return DIGEST_PREFIX + hashlib.sha256(_canonical(values).encode("utf-8")).hexdigest()


def wire_digest(params):
    """``"sha256:<64 hex digits>"`` of ``params``' canonical text (see the module)."""
    return digest_of_values(params.values())


def is_digest(text):
    """True if ``text`` has the form of a :func:`wire_digest`."""
    return isinstance(text, str) and text.startswith(DIGEST_PREFIX) and \
        len(text) == len(DIGEST_PREFIX) + 64 and set(text[len(DIGEST_PREFIX):]) <= _HEX
