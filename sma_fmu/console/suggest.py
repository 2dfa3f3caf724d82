""""Did you mean ...?" for a mistyped name (difflib's close matches)."""
import difflib

__all__ = ["did_you_mean"]


def did_you_mean(word, choices, limit=3):
    """``"did you mean 'a'?"`` (``'a', 'b' or 'c'``: the ``choices`` closest to ``word``,
    closest first), or ``""`` when none is close."""
    close = [repr(name) for name in difflib.get_close_matches(str(word), list(choices), n=limit,
                                                               cutoff=0.6)]
    if not close:
        return ""
    return f"did you mean {' or '.join([', '.join(close[:-1]), close[-1]] if len(close) > 1 else close)}?"
