"""Progress bars for every step that can take more than about 2 s, with one library (tqdm).

A bar shows on stderr only when it is a terminal, only after :data:`DELAY_S` (a quick step
shows none), and never with ``--quiet`` (:func:`configure`). Piped or redirected output
gets no bar at all. :func:`echo` prints a command's lines past a bar, :func:`note` a remark. Use :func:`bar` as a context manager (``update(n)``, ``set_postfix_str``)
or :func:`steps` over an iterable. A bar is transient: it is cleared when done, so the
command's own lines stay as they were.
"""
import sys

__all__ = ["DELAY_S", "configure", "enabled", "bar", "steps", "echo", "note"]

DELAY_S = 0.5   # a bar appears once its step has taken this long [s]


class _Settings:
    quiet = False
    notes = False


def configure(quiet=False, notes=False):
    """Silence every bar (``quiet``) or let them show on a terminal, and print :func:`note`
    lines (``notes``: the command line does); returns the previous (quiet, notes)."""
    previous = (_Settings.quiet, _Settings.notes)
    _Settings.quiet, _Settings.notes = bool(quiet), bool(notes)
    return previous


def enabled(stream=None):
    """True if bars show: not quiet and ``stream`` (default stderr) is a terminal."""
    stream = sys.stderr if stream is None else stream
    return not _Settings.quiet and bool(getattr(stream, "isatty", lambda: False)())


class _Silent:
    """What :func:`bar` gives where no bar shows: the same calls, doing nothing."""

    n = 0

    def update(self, n=1):
        self.n += n

    def set_postfix_str(self, text="", refresh=True):
        pass

    def set_description_str(self, text="", refresh=True):
        pass

    def close(self):
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def bar(total=None, label="", unit="it", stream=None, **options):
    """A tqdm bar over ``total`` ``unit`` (None: a counter) labelled ``label``, or a silent
    stand-in where bars do not show (:func:`enabled`) or ``disable=True``; other ``options``
    go to tqdm."""
    stream = sys.stderr if stream is None else stream
    if options.pop("disable", False) or not enabled(stream):
        return _Silent()
    from tqdm import tqdm

    options = {"delay": DELAY_S, "leave": False, "dynamic_ncols": True, **options}
    return tqdm(total=total, desc=label, unit=unit, file=stream, **options)


def steps(iterable, label="", unit="it", total=None, **options):
    """``iterable``, with a bar advancing once per item (see :func:`bar`)."""
    if total is None and hasattr(iterable, "__len__"):
        total = len(iterable)
    with bar(total, label, unit, **options) as shown:
        for item in iterable:
            yield item
            shown.update(1)


def echo(text, file=None):
    """Print a line of a command's own output without breaking a bar that shows (tqdm's
    write clears it, prints, and draws it again)."""
    file = sys.stdout if file is None else file
    tqdm = sys.modules.get("tqdm")
    if tqdm is not None and enabled():
        tqdm.tqdm.write(str(text), file=file)
        file.flush()
    else:
        print(text, file=file, flush=True)


def note(text):
    """``sma-fmu: text`` on stderr, a line about what a command did besides its results (an
    output folder replaced); printed by the command line only (:func:`configure`)."""
    if _Settings.notes:
        echo(f"sma-fmu: {text}", file=sys.stderr)
