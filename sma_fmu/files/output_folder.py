"""Write a command's outputs so that a failure leaves nothing half-written.

A command writes into a temporary folder beside its output folder and, only when all
of it succeeded, moves the results into place (a rename). A failure, or a Ctrl-C
(:mod:`sma_fmu.console.interrupts`: moving and cleaning up are not cut), removes the
temporary folder and leaves the output folder as it was. Once the results are in place a
Ctrl-C cannot undo them: the move records them
(:func:`~sma_fmu.console.interrupts.placed_output`) and the command line's ``interrupted``
line names them as written in full.

A rerun into the same folder replaces the previous results whole: the folder records
what sma-fmu wrote into it (:data:`MARKER`), and those entries go, so no stale result
(a scenario not run this time) stays beside the new ones. Entries sma-fmu did not write
(your notes) are kept, and said so (:func:`~sma_fmu.console.progress.note`: the command
line prints it).
"""
import contextlib
import json
import os
import shutil
import tempfile
from pathlib import Path

from sma_fmu.console.interrupts import deferred, placed_output
from sma_fmu.console.progress import note

__all__ = ["OutputError", "MARKER", "check_folder", "staged_folder", "write_file"]

MARKER = ".sma-fmu-output.json"   # {"written_by": "sma-fmu", "entries": [names]} in each folder


def _umask():
    """The process's file-creation mask (read by setting it, then restoring it)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


class OutputError(ValueError):
    """An output path cannot be used; the message names the argument and the path."""


def check_folder(out, argument="--out"):
    """Raise :class:`OutputError` when ``out`` exists and is not a folder."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise OutputError(f"{argument} {out}: exists and is not a folder")


def _writable_parent(path, argument):
    parent = Path(path).absolute().parent
    for ancestor in (parent, *parent.parents):
        if ancestor.exists():
            if not ancestor.is_dir():
                raise OutputError(f"{argument} {path}: {ancestor} is a file, not a folder")
            break
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise OutputError(f"{argument} {path}: cannot create {parent}: "
                          f"{error.strerror or error}") from None
    return parent


@contextlib.contextmanager
def staged_folder(out, argument="--out", report=True):
    """Yield an empty temporary folder beside ``out``; on success move its contents into ``out``.

    What sma-fmu wrote into ``out`` before (its :data:`MARKER`) is replaced whole; other
    entries stay (``report``: said so, and that it replaced, by a note). Raises :class:`OutputError`
    when ``out`` is an existing file or cannot be written.
    """
    out = Path(out)
    check_folder(out, argument)
    parent = _writable_parent(out, argument)
    stage = None
    try:
        with deferred():   # a Ctrl-C here: the folder is made and known, then removed below
            try:
                stage = Path(tempfile.mkdtemp(prefix=f".{out.absolute().name or 'out'}.",
                                              suffix=".partial", dir=parent))
            except OSError as error:
                raise OutputError(f"{argument} {out}: cannot write in {parent}: "
                                  f"{error.strerror or error}") from None
            stage.chmod(0o777 & ~_umask())  # mkdtemp makes it private (0700); results are for sharing
        yield stage
        with deferred():
            _commit(stage, out, argument, report)
            placed_output(out)
    finally:
        if stage is not None:
            with deferred():
                shutil.rmtree(stage, ignore_errors=True)


def _written_before(out):
    """The entries of ``out`` sma-fmu wrote there last (its marker), or () when none."""
    try:
        document = json.loads((out / MARKER).read_text(encoding="utf-8"))
        return tuple(str(name) for name in document["entries"])
    except (OSError, ValueError, KeyError, TypeError):
        return ()


def _commit(stage, out, argument, report):
    entries = sorted(entry.name for entry in stage.iterdir())
    (stage / MARKER).write_text(json.dumps({"written_by": "sma-fmu", "entries": entries}),
                                encoding="utf-8")
    try:
        if not out.exists():
            os.replace(stage, out)
            return
        previous = [name for name in _written_before(out)   # names only, never a path
                    if name not in ("", ".", "..", MARKER) and Path(name).name == name
                    and os.path.lexists(out / name)]
        for name in previous:
            _remove(out / name)
        for entry in sorted(stage.iterdir()):
            target = out / entry.name
            if target.is_dir() and not target.is_symlink():
                shutil.rmtree(target)
            os.replace(entry, target)
    except OSError as error:
        raise OutputError(f"{argument} {out}: cannot move the results into place: "
                          f"{error.strerror or error}") from None
    others = sorted(entry.name for entry in out.iterdir() if entry.name not in entries
                    and entry.name != MARKER)
    if report and previous:
        note(f"{out}: replaced the results written there before")
    if report and others:
        shown = ", ".join(others[:5]) + (f" and {len(others) - 5} more" if len(others) > 5 else "")
        note(f"{out}: kept {len(others)} entr{'y' if len(others) == 1 else 'ies'} sma-fmu "
                  f"did not write: {shown}")


def _remove(path):
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    else:
        path.unlink()


def write_file(path, data, argument="--out", final=True):
    """Write ``data`` (str or bytes) to ``path`` through a temporary file and a rename.
    ``final``: ``path`` is a command's result (recorded as placed, see the module); False for
    a file kept for a resume (a sweep's parts), which an interrupted command keeps anyway."""
    path = Path(path)
    if path.is_dir():
        raise OutputError(f"{argument} {path}: is a folder; expected a file name")
    parent = _writable_parent(path, argument)
    with deferred():   # small: written whole, or not at all
        try:
            handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".partial",
                                                 dir=parent)
        except OSError as error:
            raise OutputError(f"{argument} {path}: cannot write in {parent}: "
                              f"{error.strerror or error}") from None
        try:
            with os.fdopen(handle, "wb") as stream:
                stream.write(data.encode("utf-8") if isinstance(data, str) else data)
            os.chmod(temporary, 0o666 & ~_umask())  # mkstemp makes it private (0600)
            os.replace(temporary, path)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(temporary)
            raise
        if final:
            placed_output(path)
