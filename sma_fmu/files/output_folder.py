"""Write a command's outputs so that a failure leaves nothing half-written.

A command writes into a temporary folder beside its output folder and, only when all
of it succeeded, moves the results into place (a rename). A failure removes the
temporary folder and leaves the output folder as it was.
"""
import contextlib
import os
import shutil
import tempfile
from pathlib import Path

__all__ = ["OutputError", "check_folder", "staged_folder", "write_file"]


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
def staged_folder(out, argument="--out"):
    """Yield an empty temporary folder beside ``out``; on success move its contents into ``out``.

    Entries of ``out`` with the same names as new ones are replaced; other entries stay.
    Raises :class:`OutputError` when ``out`` is an existing file or cannot be written.
    """
    out = Path(out)
    check_folder(out, argument)
    parent = _writable_parent(out, argument)
    try:
        stage = Path(tempfile.mkdtemp(prefix=f".{out.absolute().name or 'out'}.", suffix=".partial",
                                      dir=parent))
    except OSError as error:
        raise OutputError(f"{argument} {out}: cannot write in {parent}: "
                          f"{error.strerror or error}") from None
    stage.chmod(0o777 & ~_umask())  # mkdtemp makes it private (0700); results are for sharing
    try:
        yield stage
        _commit(stage, out, argument)
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def _commit(stage, out, argument):
    try:
        if not out.exists():
            os.replace(stage, out)
            return
        for entry in sorted(stage.iterdir()):
            target = out / entry.name
            if target.is_dir() and not target.is_symlink():
                shutil.rmtree(target)
            os.replace(entry, target)
    except OSError as error:
        raise OutputError(f"{argument} {out}: cannot move the results into place: "
                          f"{error.strerror or error}") from None


def write_file(path, data, argument="--out"):
    """Write ``data`` (str or bytes) to ``path`` through a temporary file and a rename."""
    path = Path(path)
    if path.is_dir():
        raise OutputError(f"{argument} {path}: is a folder; expected a file name")
    parent = _writable_parent(path, argument)
    try:
        handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".partial", dir=parent)
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
