"""Why a number is missing: every "n/a" in a table or summary points to its reason, and each
reason is written once, under the table, not in every cell it empties.

:class:`Reasons` numbers the distinct reasons in the order they come: a missing value reads
``n/a [1]``, and :meth:`Reasons.lines` lists ``[1] heating: transformation not finished
before the turn (no austenite baseline)`` once, however many cells it explains.
"""
import math

__all__ = ["Reasons"]


class Reasons:
    """Distinct reasons for missing values, numbered as they come."""

    def __init__(self):
        self.texts = []

    def mark(self, reason):
        """``n/a [k]`` for ``reason`` (numbered on its first use)."""
        reason = reason or "no value"
        if reason not in self.texts:
            self.texts.append(reason)
        return f"n/a [{self.texts.index(reason) + 1}]"

    def cell(self, value, reason, digits=4):
        """``value`` with ``digits`` significant digits, or its mark when it is not finite."""
        return f"{value:.{digits}g}" if math.isfinite(value) else self.mark(reason)

    def lines(self):
        """``["n/a [1] reason", ...]``: each reason once."""
        return [f"n/a [{k}] {text}" for k, text in enumerate(self.texts, start=1)]

