"""Prebuilt C-family binaries (sma_fmu/fmi/packaging/prebuilt.py, prebuilt_writer.py): with them, and no compiler
at all (no cc, no mingw-w64, no zig), ``build --native`` writes the five FMUs with every FMI
2.0 platform's binary and ``build --native --fmi 3`` with every FMI 3.0 platform's, the
same bytes as compiled ones; a binary of other sources is never taken; ``compile=True``
ignores them."""
import json
import warnings
import zipfile

import pytest

from sma_fmu.fmi.packaging import prebuilt
from sma_fmu.fmi.packaging.c_family_build import NativeBuildWarning, build_native_fmus
from sma_fmu.fmi.packaging.cross_build import TARGETS
from sma_fmu.fmi.packaging.fmi3_build import build_fmi3_fmus
from sma_fmu.fmi.packaging.fmu_names import FMU_SCRIPTS
from sma_fmu.fmi.packaging.prebuilt_writer import write_prebuilt

pytestmark = pytest.mark.needs("gcc", "mingw-w64", "zig")
PLATFORMS = ("linux64", "win64", "darwin64", "win32")


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("prebuilt") / "binaries"
    assert write_prebuilt(folder) == {**{name: sorted(PLATFORMS) for name in FMU_SCRIPTS},
                                      **{prebuilt.fmi3_key(name): sorted(TARGETS) for name in FMU_SCRIPTS},
                                      "front": ["linux64", "win64"]}
    return folder


def _no_compiler(monkeypatch, folder):
    monkeypatch.setattr(prebuilt, "PREBUILT", folder)
    monkeypatch.setenv("CC", "no-such-cc")
    monkeypatch.setenv("SMA_FMU_WIN64_CC", "no-such-mingw-gcc")
    monkeypatch.setenv("SMA_FMU_ZIG_CC", "none")


def _build(path, build=build_native_fmus, **options):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fmus = build(path, **options)
    return fmus, [str(w.message) for w in caught if isinstance(w.message, NativeBuildWarning)]


def _binaries(path):
    with zipfile.ZipFile(path) as archive:
        return {n: archive.read(n) for n in archive.namelist() if n.startswith("binaries/")}


def test_without_a_compiler_the_prebuilt_binaries_are_packed(folder, native_fmus, tmp_path, monkeypatch):
    _no_compiler(monkeypatch, folder)
    fmus, problems = _build(tmp_path / "fmus")
    assert problems == []
    for name, path in fmus.items():
        binaries = _binaries(path)
        assert sorted(b.split("/")[1] for b in binaries) == sorted(PLATFORMS)
        assert binaries == _binaries(native_fmus[name]), name


def test_without_a_compiler_the_fmi3_build_packs_every_platform(folder, fmi3_fmus, tmp_path, monkeypatch):
    """The FMI 3.0 build's own prebuilt binaries (its front differs from FMI 2.0's): every
    tuple of the cross-build table; its reference result runs the x86_64-linux one."""
    _no_compiler(monkeypatch, folder)
    fmus, problems = _build(tmp_path / "fmi3", build=build_fmi3_fmus)
    assert problems == []
    for name, path in fmus.items():
        binaries = _binaries(path)
        assert sorted(b.split("/")[1] for b in binaries) == sorted(TARGETS)
        assert binaries == _binaries(fmi3_fmus[name]), name


def test_binaries_of_other_sources_are_not_taken(folder, tmp_path, monkeypatch):
    manifest = json.loads((folder / prebuilt.MANIFEST).read_text())
    manifest["SmaPwmDriver"]["sources"] = "0" * 64
    other = tmp_path / "other"
    import shutil
    shutil.copytree(folder, other)
    (other / prebuilt.MANIFEST).write_text(json.dumps(manifest))
    _no_compiler(monkeypatch, other)
    fmus, problems = _build(tmp_path / "fmus", names=["SmaPwmDriver"])
    assert problems and all("built without" in p for p in problems)
    assert _binaries(fmus["SmaPwmDriver"]) == {}


def test_compile_ignores_them(folder, tmp_path, monkeypatch):
    _no_compiler(monkeypatch, folder)
    fmus, problems = _build(tmp_path / "fmus", names=["SmaPwmDriver"], compile=True)
    assert len(problems) == len(PLATFORMS) and _binaries(fmus["SmaPwmDriver"]) == {}


def test_without_a_compiler_the_prebuilt_hosts_are_taken(tmp_path, monkeypatch):
    """sma-fmu check's C host (and the others) come prebuilt where no compiler is, but only
    when built from the same source; with a compiler they are compiled as before."""
    from sma_fmu.fmi import hosts
    folder = hosts.write_prebuilt_hosts(tmp_path / "hosts")
    assert sorted(p.name for p in folder.iterdir()) == sorted([*hosts.HOST_PROGRAMS, "manifest.json"])
    monkeypatch.setattr(hosts, "PREBUILT_HOSTS", folder)
    assert hosts.compile_host("fmi_host", tmp_path / "cache") != folder / "fmi_host"  # compiled
    monkeypatch.setenv("CC", "no-such-cc")
    for name in hosts.HOST_PROGRAMS:
        assert hosts.compile_host(name, tmp_path / "cache") == folder / name
    manifest = json.loads((folder / "manifest.json").read_text())
    manifest["fmi_host"] = "0" * 64
    (folder / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(hosts.CHostError, match="no-such-cc"):
        hosts.compile_host("fmi_host", tmp_path / "cache2")


def test_without_a_compiler_the_python_family_gets_the_prebuilt_fronts(folder, tmp_path, monkeypatch):
    """sma-fmu build (the Python family) with no compiler: the front on linux64 and win64, no
    degraded warning; the model description says the front is the prebuilt one."""
    from sma_fmu.fmi.packaging.front_build import FrontWarning
    from sma_fmu.fmi.packaging.platforms import platform_report
    from sma_fmu.fmi.packaging.pythonfmu_build import build_pythonfmu_fmus
    _no_compiler(monkeypatch, folder)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fmus = build_pythonfmu_fmus(tmp_path / "fmus", names=["SmaPwmDriver"])
    assert [w for w in caught if isinstance(w.message, FrontWarning)] == []
    report = platform_report(fmus["SmaPwmDriver"])
    assert [(status, name) for status, name, _ in report] == [("ok", "linux64"), ("ok", "win64")]
    assert all("prebuilt front" in detail for _, _, detail in report)
    with zipfile.ZipFile(fmus["SmaPwmDriver"]) as archive:
        assert archive.read("binaries/linux64/SmaPwmDriver.so") == (folder / "front" / "linux64" / "front.so").read_bytes()
