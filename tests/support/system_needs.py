"""What a test needs beyond the README's ``pip install``: system packages, root.

A test declares it with the marker ``@needs("mingw-w64", "wine64")`` (checked before its
fixtures are set up, so a missing package costs nothing) and a fixture with ``need(...)``.
Where a need is missing the test is skipped with a reason naming the Debian package and the
command that installs it (``needs mingw-w64: apt-get install gcc-mingw-w64-x86-64``); with
the environment variable ``CI=true`` it fails with the same text instead, so CI, which
installs everything (``.ci/run``), never silently skips.

Presence is decided as the build decides: the C compiler is
:func:`~sma_fmu.fmi.hosts.c_compiler` (``$CC``, else ``cc``, else ``gcc``) found on the
PATH, mingw-w64 is :func:`~sma_fmu.fmi.hosts.windows_compiler` (``$SMA_FMU_WIN64_CC``, else
``x86_64-w64-mingw32-gcc``) found on the PATH, zig is
:func:`~sma_fmu.fmi.packaging.cross_build.zig_command`. ``SMA_FMU_TESTS_WITHOUT`` (names below,
separated by spaces or commas) makes needs count as missing that a PATH cannot hide (wine64
lives in /usr/lib/wine, libpython in /usr/lib, root is who runs): the simulated fresh
machine of ``tests/project/test_system_needs.py`` uses it.
"""
import os
import re
import shutil
from pathlib import Path

import pytest

from sma_fmu.fmi.hosts import c_compiler, windows_compiler
from sma_fmu.fmi.packaging.cross_build import zig_command

__all__ = ["AARCH64_SYSROOT", "NEEDS", "WITHOUT_VARIABLE", "need", "needs", "missing", "wine_command", "by_hand_executable",
           "system_libpythons"]

WITHOUT_VARIABLE = "SMA_FMU_TESTS_WITHOUT"
DEBIAN_LIBPYTHON = Path("/usr/lib/x86_64-linux-gnu/libpython3.11.so.1.0")
AARCH64_SYSROOT = "/usr/aarch64-linux-gnu"   # Debian libc6-arm64-cross: qemu-aarch64 -L
STANDARD_FOLDERS = ("/usr/local/lib", "/usr/local/lib64", "/usr/lib/x86_64-linux-gnu",
                    "/lib/x86_64-linux-gnu", "/usr/lib64", "/lib64", "/usr/lib", "/lib")


def by_hand_executable(variable, what):
    """The executable the environment variable ``variable`` names, for the by-hand checks
    (tests/*/*_check.py: tools in no registry); a missing one fails, naming ``what`` to set."""
    path = os.environ.get(variable)
    assert path and os.access(path, os.X_OK), f"set {variable} to {what}"
    return path


def wine_command():
    """wine64 on the PATH, else where Debian's wine64 package puts it."""
    return shutil.which("wine64") or "/usr/lib/wine/wine64"


def system_libpythons():
    """{minor: path} of the libpython3.X.so.1.0 (X >= 10) in the standard library folders,
    the first found per minor (what the front's search finds without the build's Python)."""
    found = {}
    for folder in STANDARD_FOLDERS:
        for path in sorted(Path(folder).glob("libpython3.*.so.1.0")):
            match = re.fullmatch(r"libpython3\.(\d+)\.so\.1\.0", path.name)
            if match and int(match.group(1)) >= 10:
                found.setdefault(int(match.group(1)), path)
    return found


def _on_path(command):
    return shutil.which(command[0]) is not None


# name: (is it there?, what is needed, how to get it)
NEEDS = {
    "gcc": (lambda: _on_path(c_compiler()), "a C compiler (gcc, or $CC)", "apt-get install gcc"),
    "mingw-w64": (lambda: _on_path(windows_compiler()), "mingw-w64",
                  "apt-get install gcc-mingw-w64-x86-64"),
    "wine64": (lambda: Path(wine_command()).is_file(), "wine64", "apt-get install wine64"),
    "libpython3.11": (DEBIAN_LIBPYTHON.is_file, f"Debian's libpython3.11 ({DEBIAN_LIBPYTHON})",
                      "apt-get install libpython3.11"),
    "system-libpython": (lambda: bool(system_libpythons()),
                         "a system libpython 3.10 or newer (/usr/lib/x86_64-linux-gnu)",
                         "apt-get install libpython3.11 (or your release's libpython3.X)"),
    "python3": (Path("/usr/bin/python3").is_file, "Debian's python3 (/usr/bin/python3)",
                "apt-get install python3"),
    "zig": (lambda: _on_path(zig_command() or [""]),
            "zig cc (PyPI ziglang: the cross-compiler of the C family's targets)", "pip install ziglang"),
    "qemu-user": (lambda: shutil.which("qemu-aarch64") is not None and Path(AARCH64_SYSROOT).is_dir(),
                  f"qemu-aarch64 and the aarch64 C library ({AARCH64_SYSROOT})",
                  "apt-get install qemu-user libc6-arm64-cross"),
    "root": (lambda: os.geteuid() == 0 and all(shutil.which(tool) for tool in ("unshare", "chroot")),
             "root (unshare --mount, chroot)",  # both looked up on PATH (/usr/sbin)
             "run the tests as root, e.g. sudo -E python -m pytest -q"),
}


def _hidden():
    names = set(re.split(r"[\s,]+", os.environ.get(WITHOUT_VARIABLE, "").strip())) - {""}
    unknown = sorted(names - set(NEEDS))
    if unknown:
        raise ValueError(f"{WITHOUT_VARIABLE}: unknown need(s) {', '.join(unknown)}; "
                         f"known: {', '.join(NEEDS)}")
    return names


def missing(*names):
    """The reasons, one per need of ``names`` that this machine lacks (empty: all there)."""
    hidden = _hidden()
    reasons = []
    for name in names:
        present, what, how = NEEDS[name]  # KeyError: a test declares an unknown need
        if name in hidden or not present():
            reasons.append(f"needs {what}: {how}")
    return reasons


def need(*names):
    """Skip the running test (or fixture) unless every need of ``names`` is there; under
    ``CI=true`` fail with the same text instead."""
    reasons = missing(*names)
    if not reasons:
        return
    text = "; ".join(reasons)
    if os.environ.get("CI") == "true":
        pytest.fail(f"{text} (CI=true: a missing system package fails)", pytrace=False)
    pytest.skip(text)


def needs(*names):
    """Marker form of :func:`need`, checked before the test's fixtures (tests/conftest.py)."""
    for name in names:
        if name not in NEEDS:
            raise ValueError(f"unknown need {name!r}; known: {', '.join(NEEDS)}")
    return pytest.mark.needs(*names)
