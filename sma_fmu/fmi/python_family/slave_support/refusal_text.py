"""How a refusal shows what a host passed: bounded, so that a host's 5-kB string or thousand
bad value references cannot fill its log; the C family words both the same way."""

__all__ = ["SHOWN_CHARACTERS", "REFERENCES_SHOWN", "shown_value", "unknown_references"]

SHOWN_CHARACTERS = 200   # a refused string is shown up to this many characters
REFERENCES_SHOWN = 5      # unknown value references a refused get describes; the rest are counted


def shown_value(value):
    """``value`` as a refusal message shows it: its repr, a long string cut to its first
    :data:`SHOWN_CHARACTERS` characters and its length."""
    if isinstance(value, str) and len(value) > SHOWN_CHARACTERS:
        return f"{value[:SHOWN_CHARACTERS]!r}... ({len(value)} characters)"
    return repr(value)


def unknown_references(describe, references):
    """The text for ``references`` (a list) that are not variables of the type asked: the
    first :data:`REFERENCES_SHOWN` as ``describe(reference)`` gives them, the rest counted."""
    shown = [describe(reference) for reference in references[:REFERENCES_SHOWN]]
    more = len(references) - len(shown)
    return ", ".join(shown) + (f", and {more} more" if more else "")
