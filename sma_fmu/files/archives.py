"""Inspect an FMU, SSP or container archive before anything unpacks it.

An FMU or SSP is a zip archive whose entries are relative paths inside its own tree
(FMI 2.0 §2.3, SSP 1.0 §8). Archives from elsewhere (a supplier's FMU, a colleague's
SSP, a pull request) are checked here, from the central directory alone, before any host
or library sees them:

- no entry may leave the tree: no ``..`` component, no absolute path, no drive letter, no
  backslash (a Windows host reads it as a separator);
- every entry is a regular file or a folder: no symlink, device, socket or pipe;
- no name appears twice (which copy a host unpacks is undefined);
- the unpacked total is at most :data:`MAX_TOTAL_BYTES`, and no entry larger than
  :data:`RATIO_FLOOR_BYTES` compresses by more than :data:`MAX_RATIO` (a zip bomb), both read
  from the sizes the central directory declares, without unpacking;
- FMUs inside an SSP or a container FMU (``*.fmu`` entries) are inspected the same way,
  once the outer archive has passed (so a nested archive is read only within the limits).

**choice** of the limits, from what real FMUs hold: ours unpack to 2-4 MB, the
Modelica Association's Reference-FMUs to under 1 MB, large vendor FMUs with solver
libraries to some tens of MB; compiled code and XML compress by 2-20x. A few hundred MB
and a ratio of a few hundred leave every real FMU far inside and stop a bomb at once.
"""
import io
import shutil
import stat
import tempfile
import zipfile
from collections import namedtuple
from contextlib import contextmanager
from pathlib import Path

__all__ = ["MAX_TOTAL_BYTES", "MAX_RATIO", "RATIO_FLOOR_BYTES", "ArchiveProblem",
           "UnsafeArchiveError", "inspect_archive", "require_safe_archive", "safe_extract",
           "extracted"]

MAX_TOTAL_BYTES = 512 * 1024 ** 2   # [B] unpacked total of one archive, nested ones included
MAX_RATIO = 300.0                   # [1] unpacked / compressed size of one entry
RATIO_FLOOR_BYTES = 1024 ** 2       # [B] entries smaller than this are not ratio-checked
_NESTED_SUFFIXES = (".fmu",)

ArchiveProblem = namedtuple("ArchiveProblem", ["entry", "rule"])
ArchiveProblem.__doc__ = "One unsafe entry: its name as stored (``outer.ssp[inner.fmu]/name`` when nested) and the rule it breaks."


class UnsafeArchiveError(ValueError):
    """An archive breaks a rule of :func:`inspect_archive`; the message names the file, the entry and the rule."""

    def __init__(self, path, problems):
        self.path, self.problems = str(path), list(problems)
        first = self.problems[0]
        more = f" (and {len(self.problems) - 1} more)" if len(self.problems) > 1 else ""
        super().__init__(f"{path}: unsafe archive entry {first.entry!r}: {first.rule}{more}")


def _name_problem(name):
    """The rule an entry name breaks, or None."""
    if "\\" in name:
        return "backslash in the name (a path separator on Windows)"
    if name.startswith("/"):
        return "absolute path"
    if len(name) >= 2 and name[1] == ":" and name[0].isalpha():
        return "drive letter"
    if ".." in name.split("/"):
        return "'..' component: the entry would land outside the unpacked folder"
    if "\x00" in name:
        return "NUL character in the name"
    return None


def _kind_problem(info):
    """The rule an entry's file type breaks, or None (only Unix-made archives record a type)."""
    if info.create_system != 3:  # 3: Unix; others carry no file type
        return None
    mode = info.external_attr >> 16
    if stat.S_IFMT(mode) == 0 or stat.S_ISREG(mode) or stat.S_ISDIR(mode):
        return None  # no type recorded (permission bits alone), a file or a folder
    if stat.S_ISLNK(mode):
        return "symbolic link"
    return f"not a regular file (mode {oct(stat.S_IFMT(mode))})"


def _entry_problems(infos, label):
    problems, seen, total = [], set(), 0
    for info in infos:
        name = info.filename
        entry = f"{label}{name}"
        rule = _name_problem(name) or _kind_problem(info)
        if rule is None and name in seen:
            rule = "duplicate name"
        seen.add(name)
        total += info.file_size
        if rule is None and info.file_size >= RATIO_FLOOR_BYTES:
            ratio = info.file_size / max(info.compress_size, 1)
            if ratio > MAX_RATIO:
                rule = (f"compression ratio {ratio:.0f} above {MAX_RATIO:.0f} "
                        f"({info.file_size} bytes unpacked)")
        if rule is not None:
            problems.append(ArchiveProblem(entry, rule))
    return problems, total


def _inspect(archive, label, budget):
    infos = archive.infolist()
    problems, total = _entry_problems(infos, label)
    if total > budget:
        problems.append(ArchiveProblem(f"{label}*", f"unpacked total {total} bytes above the "
                                                    f"limit of {MAX_TOTAL_BYTES} bytes"))
    if problems:
        return problems, total
    for info in infos:
        if info.filename.lower().endswith(_NESTED_SUFFIXES) and not info.is_dir():
            inner_label = f"{label}{info.filename}/"
            try:
                with zipfile.ZipFile(io.BytesIO(archive.read(info))) as inner:
                    inner_problems, inner_total = _inspect(inner, inner_label, budget - total)
            except (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, EOFError) as error:
                inner_problems, inner_total = [ArchiveProblem(inner_label, f"nested archive unreadable: {error}")], 0
            problems += inner_problems
            total += inner_total
    return problems, total


def inspect_archive(path):
    """The :class:`ArchiveProblem` list of the archive ``path`` (empty: safe to unpack).

    Reads the central directory; a nested FMU is read only after its container passed.
    A file that is not a zip archive gives one problem naming it so.
    """
    try:
        with zipfile.ZipFile(path) as archive:
            return _inspect(archive, "", MAX_TOTAL_BYTES)[0]
    except (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, EOFError) as error:
        return [ArchiveProblem("", f"not a readable zip archive ({error})")]


def require_safe_archive(path):
    """Raise :class:`UnsafeArchiveError` unless :func:`inspect_archive` finds nothing."""
    problems = inspect_archive(path)
    if problems:
        raise UnsafeArchiveError(path, problems)
    return Path(path)


def safe_extract(path, folder, wanted=None):
    """Inspect ``path``, then unpack it into ``folder`` [a new, empty folder]; returns ``folder``.
    ``wanted``: a function of a member's name, whether to unpack it (None: every member)."""
    require_safe_archive(path)
    folder = Path(folder)
    with zipfile.ZipFile(path) as archive:
        names = None if wanted is None else [n for n in archive.namelist() if wanted(n)]
        archive.extractall(folder, names)
    return folder


@contextmanager
def extracted(path, prefix="sma_fmu_"):
    """Context manager: ``path`` inspected and unpacked into a fresh temporary folder,
    removed on leaving, errors included."""
    folder = tempfile.mkdtemp(prefix=prefix)
    try:
        yield safe_extract(path, folder)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
