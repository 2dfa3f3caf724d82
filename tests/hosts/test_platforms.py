"""Honest platforms (issue 20): an FMU lists a platform only where its binary is the native
front, or says what is degraded there, in modelDescription.xml and in ``sma-fmu check``.

Before, every FMU carried pythonfmu's own win64 DLL (fmpy: supported on linux64 and win64),
with none of the front's guarantees and nothing saying so. Now:
- with mingw-w64 the win64 binary is the front; without it, win64 is left out (warned);
- without a C compiler, linux64 keeps pythonfmu's binary, and the FMU says what that loses;
- ``sma-fmu build`` refuses a machine whose architecture pythonfmu's binaries do not match.
What needs gcc or mingw-w64 says so (tests/support/system_needs.py).
"""
import warnings
import zipfile

import pytest
from fmpy import supported_platforms

from sma_fmu.cli import main
from sma_fmu.fmi.packaging.build import build_fmu
from sma_fmu.fmi.packaging.front_build import FrontWarning, remove_front
from sma_fmu.fmi.packaging.platforms import (DEGRADED, FRONT_MARKER, UnsupportedPlatformError,
                                   check_build_machine, platform_report)
from system_needs import needs


def _build(tmp_path, monkeypatch, **environment):
    for key, value in environment.items():
        monkeypatch.setenv(key, value)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        path = build_fmu("SmaActuator", tmp_path / "out")
    return path, [str(w.message) for w in caught if issubclass(w.category, FrontWarning)]


@needs("gcc", "mingw-w64")
def test_every_listed_platform_carries_the_front(fmus):
    for name, path in fmus.items():
        assert supported_platforms(str(path)) == ["linux64", "win64"], name
        with zipfile.ZipFile(path) as archive:
            for binary in (f"binaries/linux64/{name}.so", f"binaries/win64/{name}.dll"):
                assert FRONT_MARKER in archive.read(binary), binary
        assert [(status, platform) for status, platform, _ in platform_report(path)] == [
            ("ok", "linux64"), ("ok", "win64")]


@needs("gcc")  # linux64 "ok": its front
def test_without_mingw_win64_is_left_out_and_the_build_says_so(tmp_path, monkeypatch):
    path, messages = _build(tmp_path, monkeypatch, SMA_FMU_WIN64_CC=str(tmp_path / "no-mingw-gcc"))
    assert supported_platforms(str(path)) == ["linux64"]
    assert not any(n.startswith("binaries/win64/") for n in zipfile.ZipFile(path).namelist())
    assert any("without win64" in m and "no-mingw-gcc not found" in m and "gcc-mingw-w64-x86-64" in m
               for m in messages), messages
    assert [status for status, _, _ in platform_report(path)] == ["ok"]


@needs("gcc", "mingw-w64")  # the C host of the check; win64 "ok"
def test_without_a_c_compiler_linux64_says_what_is_degraded(tmp_path, monkeypatch, capsys):
    path, messages = _build(tmp_path, monkeypatch, CC=str(tmp_path / "no-cc"))
    assert any("linux64" in m and "no-cc" in m and "LD_PRELOAD" in m for m in messages), messages
    description = zipfile.ZipFile(path).read("modelDescription.xml").decode()
    assert 'name="linux64"' in description and 'front="false"' in description
    assert DEGRADED.split(":")[0] in description
    report = {platform: (status, detail) for status, platform, detail in platform_report(path)}
    assert report["linux64"][0] == "warn" and "refused calls return fmi2OK" in report["linux64"][1]
    assert report["win64"][0] == "ok"
    monkeypatch.delenv("CC")
    assert main(["check", str(path)]) == 1  # what it says is so: the C host cannot load it
    out = capsys.readouterr().out
    assert any(line.startswith("FAIL ") and "C host (libcosim)" in line and "Error loading" in line
               for line in out.splitlines()), out
    lines = [line for line in out.splitlines() if ": platform " in line]
    assert lines[0].startswith("warn ") and "platform linux64" in lines[0] and "degraded: " in lines[0]
    assert lines[1].startswith("ok ") and "platform win64" in lines[1]


@needs("gcc", "mingw-w64")
def test_check_fails_an_fmu_whose_binaries_and_description_disagree(fmus, tmp_path, capsys):
    plain = remove_front(fmus["SmaActuator"], tmp_path / "pythonfmu-only.fmu")  # as before issue 20
    assert [status for status, _, _ in platform_report(plain)] == ["FAIL", "FAIL"]
    lied = tmp_path / "lied.fmu"
    with zipfile.ZipFile(fmus["SmaActuator"]) as source, zipfile.ZipFile(lied, "w") as target:
        for item in source.infolist():
            data = source.read(item.filename)
            if item.filename == "binaries/win64/SmaActuator.dll":
                data = source.read("binaries/win64/SmaActuator_pythonfmu.dll")
            target.writestr(item, data)
    report = {platform: (status, detail) for status, platform, detail in platform_report(lied)}
    assert report["linux64"][0] == "ok"
    assert report["win64"] == ("FAIL", "modelDescription.xml says front=true, but "
                                       "binaries/win64/SmaActuator.dll (x86-64) is not the front")
    assert main(["check", str(lied)]) == 1
    assert "FAIL  " + str(lied) + ": platform win64: " in capsys.readouterr().out


@pytest.mark.parametrize("machine", ["aarch64", "arm64", "i686"])
def test_a_machine_pythonfmu_has_no_binary_for_is_refused(machine):
    with pytest.raises(UnsupportedPlatformError, match=f"this machine is {machine} .*pythonfmu 0.7.0 "
                       "ships binaries for linux64: x86-64, win64: x86-64 only"):
        check_build_machine(machine)
    check_build_machine("x86_64")
    check_build_machine("AMD64")  # Windows' name for it


def test_sma_fmu_build_refuses_on_such_a_machine(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr("platform.machine", lambda: "aarch64")
    assert main(["build", "--out", str(tmp_path / "out")]) == 2
    error = capsys.readouterr().err
    assert error.startswith("sma-fmu: error: this machine is aarch64") and "x86-64" in error
    assert not (tmp_path / "out").exists()
