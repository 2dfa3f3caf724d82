"""Each FMU file unpacked once per process, shared by its instances (:class:`FmuInstance`).

Unpacking an FMU takes 8-70 ms, more than the rest of making an instance; the closed loop
and the bench make several instances of the same files per process. Only what running it
needs is unpacked: its model description, ``resources/`` and the binaries of the platforms
asked for (default: this process's; a win64 host under wine asks for win64's), not its C
sources, documentation, ``extra/`` or other platforms' binaries (of a native FMU's 103
files, 4: a fifth of the bytes of all but sources and documentation). A platform asked for
later is added to the same folder. The cache key is the file's resolved path, size and
modification time [ns]: a rebuilt FMU at the same path gets a fresh folder, and the old folder is removed once no instance uses it.

- :func:`acquire` gives an :class:`Unpacked` (folder and model description) and counts a
  user; :func:`release` ends the use. The archive is inspected
  (:func:`~sma_fmu.files.archives.require_safe_archive`) before it is unpacked.
- Folders are removed when the process exits (``atexit``, and multiprocessing's exit
  finalizers, as its child processes skip ``atexit``). Each folder records the process that
  made it: a forked child may use its parent's folders but never removes them.
- Folders of processes that died without removing them (killed, crashed) are removed by
  the next process that unpacks (:func:`remove_stale`, once per process): a folder's name
  holds the process id of its maker, and one whose process no longer exists is stale
  (POSIX only: on Windows they stay).
- A lock makes it thread-safe (dask may make instances from threads).
- ``SMA_FMU_UNPACK_EACH=1`` in the environment: every :func:`acquire` unpacks into a folder
  of its own, removed at its :func:`release` (the behaviour before the cache).
"""
import atexit
import os
import re
import shutil
import sys
import tempfile
import threading
from pathlib import Path

from sma_fmu.files.archives import require_safe_archive, safe_extract
from sma_fmu.fmi.driving.description import described

__all__ = ["Unpacked", "WIN64", "acquire", "release", "folders", "remove_stale",
           "UNPACK_EACH_VARIABLE"]

UNPACK_EACH_VARIABLE = "SMA_FMU_UNPACK_EACH"
_PREFIX = "sma_fmu_unpacked_"
_RUN = ("resources/",)   # with the model description and binaries/<platform>/: what a host reads
WIN64 = ("win64", "x86_64-windows")   # the binaries/ folders (FMI 2.0, 3.0) of a win64 host


class Unpacked:
    """One unpacked FMU: ``folder`` (str), ``description`` (fmpy's ModelDescription, shared:
    read only) and the number of instances using it."""

    __slots__ = ("folder", "description", "key", "pid", "users", "cached", "platforms")

    def __init__(self, folder, description, key, cached, platforms):
        self.folder, self.description, self.key = folder, description, key
        self.platforms = set(platforms)   # the binaries/ folders unpacked
        self.pid = os.getpid()  # the process that made the folder, the only one to remove it
        self.users = 0
        self.cached = cached    # False: replaced by a newer file, or SMA_FMU_UNPACK_EACH


_LOCK = threading.Lock()
_CACHE = {}   # key -> Unpacked, the current folder of each file
_OWNED = []   # every folder this process made and has not removed yet
_FINALIZER_PID = [None]  # the process whose multiprocessing finalizer is registered
_SWEPT_PID = [None]      # the process that looked for stale folders (remove_stale)
_FOLDER_NAME = re.compile(re.escape(_PREFIX) + r"(\d+)_")


def _after_fork_in_child():
    global _LOCK
    _LOCK = threading.Lock()  # another thread may have held it at the fork


os.register_at_fork(after_in_child=_after_fork_in_child)


def _key(path):
    try:
        status = os.stat(path)
    except OSError:
        require_safe_archive(path)  # the same error as an unreadable archive gives
        raise
    return (str(Path(path).resolve()), status.st_size, status.st_mtime_ns)


def _remove(unpacked):
    """Remove ``unpacked``'s folder if this process made it (call with the lock held)."""
    if unpacked.pid == os.getpid():
        shutil.rmtree(unpacked.folder, ignore_errors=True)
        if unpacked in _OWNED:
            _OWNED.remove(unpacked)
    if _CACHE.get(unpacked.key) is unpacked:
        del _CACHE[unpacked.key]


def _remove_own():
    """Remove every folder this process made (at exit)."""
    with _LOCK:
        for unpacked in [u for u in _OWNED if u.pid == os.getpid()]:
            _remove(unpacked)


atexit.register(_remove_own)


def _register_child_exit():
    """multiprocessing's children end with os._exit (no atexit) but run its finalizers."""
    util = sys.modules.get("multiprocessing.util")
    if util is not None and _FINALIZER_PID[0] != os.getpid():
        _FINALIZER_PID[0] = os.getpid()
        util.Finalize(None, _remove_own, exitpriority=0)


def _process_exists(pid):
    """Whether process ``pid`` exists (POSIX; True when it cannot be told)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:   # another user's process (EPERM), or no answer: it may exist
        return True
    return True


def remove_stale(folder=None):
    """Remove the unpacked folders in ``folder`` (default: the temporary folder) whose
    process no longer exists (it was killed or crashed before its exit removed them); the
    names of those removed. POSIX only (on Windows os.kill cannot ask): none there."""
    if os.name != "posix":
        return []
    folder = Path(folder or tempfile.gettempdir())
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for entry in entries:
        match = _FOLDER_NAME.match(entry.name)
        if match is None or not entry.is_dir(follow_symlinks=False):
            continue
        pid = int(match.group(1))
        if pid == os.getpid() or _process_exists(pid):
            continue
        shutil.rmtree(entry.path, ignore_errors=True)
        if not os.path.exists(entry.path):
            removed.append(entry.name)
    return removed


def _platforms(platforms):
    """The binaries/ folder names ``platforms`` (None: this process's, FMI 2.0 and 3.0 names)."""
    if platforms is None:
        import fmpy
        return (fmpy.platform, fmpy.platform_tuple)
    return tuple(platforms)


def _binaries(platforms):
    """Whether to unpack a member: the binaries of ``platforms`` only."""
    folders = tuple(f"binaries/{platform}/" for platform in platforms)
    return lambda name: name.startswith(folders)


def _unpack(path, key, cached, platforms):
    if _SWEPT_PID[0] != os.getpid():   # once per process: what killed ones left behind
        _SWEPT_PID[0] = os.getpid()
        remove_stale()
    folder = tempfile.mkdtemp(prefix=f"{_PREFIX}{os.getpid()}_")
    binaries = _binaries(platforms)
    try:
        # the archive inspected once, before fmpy reads anything of it
        safe_extract(path, folder, lambda name: (name == "modelDescription.xml"
                                                 or name.startswith(_RUN) or binaries(name)))
        description = described(key)   # read once per file version
    except BaseException:
        shutil.rmtree(folder, ignore_errors=True)
        raise
    unpacked = Unpacked(folder, description, key, cached, platforms)
    _OWNED.append(unpacked)
    _register_child_exit()
    return unpacked


def acquire(path, platforms=None):
    """The :class:`Unpacked` FMU file ``path``, unpacked now or earlier; counts one user.
    ``platforms``: the binaries/ folders its host loads (None: this process's platform;
    :data:`WIN64` for a win64 host under wine).

    Raises :class:`~sma_fmu.files.archives.UnsafeArchiveError` for an unsafe or unreadable
    archive, :class:`~sma_fmu.fmi.driving.description.FmuFileError` for a zip that is no usable FMU.
    """
    path, platforms = str(path), _platforms(platforms)
    key = _key(path)
    each = os.environ.get(UNPACK_EACH_VARIABLE, "") not in ("", "0")
    with _LOCK:
        unpacked = None if each else _CACHE.get(key)
        if unpacked is not None and not unpacked.platforms.issuperset(platforms):
            _add_platforms(unpacked, path, platforms)
        if unpacked is None:
            unpacked = _unpack(path, key, cached=not each, platforms=platforms)
            if not each:
                if _key(path) != key:   # changed while unpacking: use once, cache nothing
                    unpacked.cached = False
                else:
                    _retire_older(key)
                    _CACHE[key] = unpacked
        unpacked.users += 1
        return unpacked


def _add_platforms(unpacked, path, platforms):
    """Unpack the binaries of ``platforms`` into the folder of ``unpacked`` too (call with
    the lock held; the cache key just matched the file: the same version)."""
    missing = [p for p in platforms if p not in unpacked.platforms]
    safe_extract(path, unpacked.folder, _binaries(missing))
    unpacked.platforms.update(missing)


def _retire_older(key):
    """Folders of earlier versions of the file at ``key``'s path: removed when unused."""
    for older in [u for k, u in _CACHE.items() if k[0] == key[0] and k != key]:
        del _CACHE[older.key]
        older.cached = False
        if older.users == 0:
            _remove(older)


def release(unpacked):
    """End one use of ``unpacked``; a folder no longer current is removed at its last use."""
    with _LOCK:
        unpacked.users = max(unpacked.users - 1, 0)
        if unpacked.users == 0 and not unpacked.cached:
            _remove(unpacked)


def folders():
    """{resolved path: folder} of the current folders (for tests and diagnostics)."""
    with _LOCK:
        return {key[0]: unpacked.folder for key, unpacked in _CACHE.items()}
