"""JSON the way every reader accepts it: no NaN or Infinity, ever.

Python's ``json`` writes ``NaN`` and ``Infinity``, which are not JSON. :func:`json_text`
writes ``null`` in their place and lists each such value, with what it was, under
``non_finite_values`` so the reason is not lost.
"""
import json
import math

__all__ = ["json_text", "finite_document"]


def finite_document(value, notes, where=""):
    """A copy of ``value`` with non-finite floats replaced by None; ``notes`` collects {where: text}."""
    if isinstance(value, float) and not math.isfinite(value):
        notes[where or "(top)"] = repr(value)
        return None
    if isinstance(value, dict):
        return {key: finite_document(item, notes, f"{where}.{key}" if where else str(key))
                for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite_document(item, notes, f"{where}[{index}]") for index, item in enumerate(value)]
    return value


def json_text(document, indent=2):
    """``document`` as strict JSON text; non-finite numbers become null and are listed."""
    notes = {}
    clean = finite_document(document, notes)
    if notes and isinstance(clean, dict):
        clean["non_finite_values"] = {key: f"{text}: not representable in JSON, written as null"
                                      for key, text in notes.items()}
    return json.dumps(clean, indent=indent, allow_nan=False) + "\n"
