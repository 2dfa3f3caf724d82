"""Archives from elsewhere: unsafe FMUs and SSPs are refused before anything unpacks them (issue 31).

Each unsafe archive is one of our own FMUs or SSPs with one entry added. The tests show
that ``sma-fmu check`` fails it naming the entry, that no host or library is handed it,
that nothing lands outside a temporary folder (a decoy folder stays empty), and that a
good FMU and SSP still pass the inspection.
"""
import io
import shutil
import stat
import subprocess
import sys
import warnings
import zipfile

import pytest

from sma_fmu.cli import main
from sma_fmu.files.archives import (MAX_RATIO, MAX_TOTAL_BYTES, UnsafeArchiveError,
                                    inspect_archive, safe_extract)
from sma_fmu.fmi.driving.instance import FmuInstance
from sma_fmu.systems.c_host import run_c_host
from sma_fmu.systems.check import check_file
from sma_fmu.systems.hosts import run_ssp_libcosim

SCENARIO = "load-step-pi+ff-adaptive"


@pytest.fixture(scope="module")
def good_ssp(fmu_dir, tmp_path_factory):
    folder = tmp_path_factory.mktemp("ssp")
    assert main(["export", "ssp", SCENARIO, "--out", str(folder), "--fmus", str(fmu_dir)]) == 0
    return folder / f"{SCENARIO}.ssp"


@pytest.fixture
def decoy(tmp_path):
    """A folder that nothing may ever write into."""
    folder = tmp_path / "decoy"
    folder.mkdir()
    return folder


def _with_entry(source, target, info, data=b"x"):
    """Copy archive ``source`` to ``target`` with one more entry (``info``: a name or a ZipInfo)."""
    shutil.copyfile(source, target)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # zipfile warns about a duplicate name: that is the point
        with zipfile.ZipFile(target, "a", zipfile.ZIP_DEFLATED) as archive:
            archive.writestr(info, data)
    return target


def _traversal(decoy):
    """An entry name that climbs out of any unpack folder into ``decoy``."""
    return "../" * 40 + str(decoy).lstrip("/") + "/slip.txt"


def _symlink(name, target="/etc/passwd"):
    info = zipfile.ZipInfo(name)
    info.create_system = 3
    info.external_attr = (stat.S_IFLNK | 0o777) << 16
    return info, target.encode()


def _failures(path):
    return [(r.check, r.detail) for r in check_file(path) if r.status == "FAIL"]


def test_good_fmus_and_ssp_pass_the_inspection(fmus, good_ssp):
    for path in [*fmus.values(), good_ssp]:
        assert inspect_archive(path) == []


@pytest.mark.parametrize("make, rule", [
    (lambda decoy: (_traversal(decoy), b"slip"), "'..' component"),
    (lambda decoy: (str(decoy / "absolute.txt"), b"abs"), "absolute path"),
    (lambda decoy: ("C:/windows/evil.dll", b"dll"), "drive letter"),
    (lambda decoy: ("resources\\..\\..\\evil.txt", b"bs"), "backslash"),
    (lambda decoy: _symlink("resources/link"), "symbolic link"),
    (lambda decoy: ("modelDescription.xml", b"<fmiModelDescription/>"), "duplicate name"),
], ids=["traversal", "absolute", "drive", "backslash", "symlink", "duplicate"])
def test_check_fails_an_unsafe_fmu_naming_the_entry_and_runs_nothing(fmus, tmp_path, decoy, make, rule):
    name, data = make(decoy)
    path = _with_entry(fmus["SmaActuator"], tmp_path / "Unsafe.fmu", name, data)
    failures = _failures(path)
    entry = name.filename if isinstance(name, zipfile.ZipInfo) else name
    assert failures and all(check == "archive" for check, _ in failures)
    assert any(repr(entry) in detail and rule in detail for _, detail in failures)
    with pytest.raises(UnsafeArchiveError, match=rule):
        FmuInstance(path, "unsafe")
    with pytest.raises(UnsafeArchiveError, match=rule):
        run_c_host("fmu", path, 1e-3, 10)
    assert list(decoy.iterdir()) == []


def test_cli_check_names_the_traversal_entry_and_writes_nothing_outside(fmus, tmp_path, decoy):
    path = _with_entry(fmus["SmaActuator"], tmp_path / "Slip.fmu", _traversal(decoy), b"slip")
    result = subprocess.run([sys.executable, "-m", "sma_fmu", "check", str(path)],
                            capture_output=True, text=True, cwd=tmp_path)
    assert result.returncode == 1, result.stderr
    lines = [line for line in result.stdout.splitlines() if line.startswith("FAIL")]
    assert len(lines) == 1 and "slip.txt" in lines[0] and "'..' component" in lines[0]
    assert not any(line.startswith("ok") for line in result.stdout.splitlines())
    assert "Traceback" not in result.stderr
    assert list(decoy.iterdir()) == []


def test_traversal_at_the_ssp_level_and_a_nested_unsafe_fmu_are_refused(good_ssp, fmus, tmp_path, decoy):
    top = _with_entry(good_ssp, tmp_path / "top.ssp", _traversal(decoy), b"slip")
    assert any("slip.txt" in detail for _, detail in _failures(top))
    with pytest.raises(UnsafeArchiveError, match="'..' component"):
        run_ssp_libcosim(top, 10, ["plant.R"])

    inner = _with_entry(fmus["SmaActuator"], tmp_path / "inner.fmu", *_symlink("resources/link"))
    nested = tmp_path / "nested.ssp"
    with zipfile.ZipFile(good_ssp) as source, zipfile.ZipFile(nested, "w", zipfile.ZIP_DEFLATED) as target:
        for item in source.infolist():
            data = source.read(item)
            if item.filename.endswith("SmaActuator.fmu"):
                data = inner.read_bytes()
                nested_name = item.filename
            target.writestr(item, data)
    problems = inspect_archive(nested)
    assert [p.entry for p in problems] == [f"{nested_name}/resources/link"]
    assert any(f"{nested_name}/resources/link" in detail for _, detail in _failures(nested))
    assert list(decoy.iterdir()) == []


def _bomb(source, target, size):
    """``source`` plus resources/zeros.bin: ``size`` bytes of zeros, deflated (about size / 1000)."""
    shutil.copyfile(source, target)
    chunk = bytes(16 * 1024 ** 2)
    with zipfile.ZipFile(target, "a", zipfile.ZIP_DEFLATED, compresslevel=9) as archive, \
            archive.open("resources/zeros.bin", "w", force_zip64=True) as entry:
        for _ in range(size // len(chunk)):
            entry.write(chunk)
    return target


def test_a_bomb_is_refused_from_the_central_directory_without_reading_an_entry(fmus, tmp_path, monkeypatch):
    size = 1024 ** 3  # 1 GiB unpacked
    path = _bomb(fmus["SmaActuator"], tmp_path / "Bomb.fmu", size)
    assert path.stat().st_size < 16 * 1024 ** 2
    opened = []
    real_open = zipfile.ZipFile.open

    def watched_open(self, name, *args, **kwargs):
        opened.append(getattr(name, "filename", name))
        return real_open(self, name, *args, **kwargs)

    monkeypatch.setattr(zipfile.ZipFile, "open", watched_open)
    failures = _failures(path)
    assert opened == []  # no entry was read: not the bomb, not even the model description
    assert any("'resources/zeros.bin'" in d and f"above {MAX_RATIO:.0f}" in d for _, d in failures)
    assert any(f"limit of {MAX_TOTAL_BYTES} bytes" in d for _, d in failures)
    with pytest.raises(UnsafeArchiveError, match="compression ratio"):
        safe_extract(path, tmp_path / "never")
    assert not (tmp_path / "never").exists()


def test_an_archive_that_is_no_zip_is_one_problem_not_an_exception(tmp_path):
    path = tmp_path / "broken.fmu"
    path.write_bytes(b"PK\x03\x04 not really")
    problems = inspect_archive(path)
    assert len(problems) == 1 and "not a readable zip archive" in problems[0].rule
    assert inspect_archive(io.BytesIO(b"")) != []
