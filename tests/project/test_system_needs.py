"""A fresh machine (issue 27): without mingw-w64, wine64, a C compiler or root, the tests that
need them skip, naming the Debian package and its install command; under CI=true they fail.

The machine is simulated in a child pytest: a PATH holding only a ``python`` link (no cc, gcc,
x86_64-w64-mingw32-gcc), and ``SMA_FMU_TESTS_WITHOUT`` for what a PATH cannot hide (wine64
in /usr/lib/wine, Debian's libpython, root). The tests chosen declare their needs as markers
or in the session's fixtures, so each is decided before anything is built; two (four with
parameters) need nothing and pass either way.
"""
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from system_needs import WITHOUT_VARIABLE, missing, need

TESTS = Path(__file__).parents[1]
CHOSEN = [
    "hosts/test_platforms.py::test_every_listed_platform_carries_the_front",            # mingw-w64
    "hosts/test_platforms_windows.py::test_a_python_of_the_registry_is_found_and_an_old_one_refused",
    "hosts/test_c_host.py::test_remove_front_gives_back_pythonfmus_binary",             # mingw-w64
    "systems/test_systems_cli.py::test_check_passes_on_everything_built",               # gcc, mingw-w64
    "hosts/test_platforms_linux.py::test_no_python_at_all_gives_null_and_one_line_naming_what_was_tried",
    "hosts/test_c_host.py::test_plain_c_host_equals_the_library",                       # fixtures: gcc
    "hosts/test_platforms.py::test_a_machine_pythonfmu_has_no_binary_for_is_refused",   # nothing (3)
    "hosts/test_c_host.py::test_host_environment_drops_ld_preload_and_the_keys_asked",  # nothing
]
REASONS = {
    "mingw-w64": "needs mingw-w64: apt-get install gcc-mingw-w64-x86-64",
    "wine64": "needs wine64: apt-get install wine64",
    "gcc": "needs a C compiler (gcc, or $CC): apt-get install gcc",
    "root": "needs root (unshare --mount, chroot): run the tests as root",
}


def _fresh_machine(tmp_path, ci):
    """The child pytest's (summary line, output) on the simulated fresh machine."""
    bin_folder = tmp_path / "bin"
    bin_folder.mkdir(parents=True)
    # runs this Python by its own path (a link would lose a venv's packages: a venv is found
    # from the path the interpreter was started by)
    launcher = bin_folder / "python"
    launcher.write_text(f'#!/bin/sh\nexec {shlex.quote(sys.executable)} "$@"\n')
    launcher.chmod(0o755)
    environment = {k: v for k, v in os.environ.items()
                   if k not in ("CI", "CC", "SMA_FMU_WIN64_CC", WITHOUT_VARIABLE, "PYTEST_ADDOPTS")}
    environment.update(PATH=str(bin_folder), COLUMNS="1000",  # summary lines kept whole
                       **{WITHOUT_VARIABLE: "wine64 root libpython3.11"})
    if ci:
        environment["CI"] = "true"
    result = subprocess.run(
        [str(bin_folder / "python"), "-m", "pytest", "-q", "-rsE", "-p", "no:cacheprovider",
         "--basetemp", str(tmp_path / "child"), *CHOSEN],
        cwd=TESTS, env=environment, capture_output=True, text=True, timeout=600)
    lines = result.stdout.strip().splitlines()
    return (lines[-1] if lines else ""), result.stdout + result.stderr, result.returncode


def test_the_helper_reads_the_build_compilers_and_the_variable(monkeypatch, tmp_path):
    monkeypatch.delenv(WITHOUT_VARIABLE, raising=False)
    monkeypatch.setenv("CC", str(tmp_path / "no-cc"))  # what the build would run
    monkeypatch.setenv("SMA_FMU_WIN64_CC", str(tmp_path / "no-mingw-gcc"))
    assert missing("gcc", "mingw-w64") == [REASONS["gcc"], REASONS["mingw-w64"]]
    monkeypatch.setenv("CC", sys.executable)  # any program found counts as there
    monkeypatch.setenv(WITHOUT_VARIABLE, "wine64,gcc")
    assert missing("gcc", "wine64") == [REASONS["gcc"], REASONS["wine64"]]
    monkeypatch.setenv(WITHOUT_VARIABLE, "gcc mingw")
    with pytest.raises(ValueError, match="unknown need.*mingw"):
        missing("gcc")


def test_need_skips_and_fails_under_ci(monkeypatch):
    monkeypatch.setenv(WITHOUT_VARIABLE, "wine64")
    monkeypatch.delenv("CI", raising=False)
    with pytest.raises(pytest.skip.Exception, match=re.escape(REASONS["wine64"])):
        need("wine64")
    monkeypatch.setenv("CI", "true")
    with pytest.raises(pytest.fail.Exception, match=re.escape(REASONS["wine64"])):
        need("wine64")
    monkeypatch.setenv("CI", "false")  # only "true" turns skips into failures
    with pytest.raises(pytest.skip.Exception):
        need("wine64")


def test_a_fresh_machine_skips_naming_packages_and_ci_fails_the_same_tests(tmp_path):
    summary, output, code = _fresh_machine(tmp_path / "plain", ci=False)
    assert code == 0, output
    assert re.fullmatch(r"4 passed, 6 skipped in [\d.]+s", summary), output
    skipped = [line for line in output.splitlines() if line.startswith("SKIPPED")]
    for reason in REASONS.values():
        assert any(reason in line for line in skipped), (reason, skipped)
    summary, output, code = _fresh_machine(tmp_path / "ci", ci=True)
    assert code == 1, output
    assert re.fullmatch(r"4 passed, 6 errors in [\d.]+s", summary), output
    errors = [line for line in output.splitlines() if line.startswith("ERROR")]
    assert len(errors) == 6 and all("(CI=true: a missing system package fails)" in e for e in errors)
    for reason in REASONS.values():
        assert any(reason in line for line in errors), (reason, errors)
