"""The wheel from the build backend alone (build_backend/wheel_backend.py): ``pip wheel`` of a
copy of the checkout, in pip's isolated build environment, makes a wheel holding every
prebuilt binary where gcc, mingw-w64 and zig are; without them a wheel that compiles where
it runs, and the build says so; ``SMA_FMU_PREBUILT=require`` then fails instead. The build
leaves the checkout as it found it. Slow: each build sets up its own environment, and the
one with the compilers compiles for minutes (less with the compilers' cache warm)."""
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from sma_fmu.fmi.hosts import HOST_PROGRAMS
from sma_fmu.fmi.packaging.cross_build import TARGETS, fmi2_targets
from sma_fmu.fmi.packaging.fmu_names import FMU_SCRIPTS
from sma_fmu.fmi.packaging.prebuilt import fmi3_key

REPO = Path(__file__).resolve().parents[2]
PREBUILT = "sma_fmu/fmi/packaging/prebuilt_binaries"
HOSTS = "sma_fmu/fmi/hosts/prebuilt"
NO_COMPILERS = {"CC": "no-such-cc", "SMA_FMU_WIN64_CC": "no-such-mingw-gcc", "SMA_FMU_ZIG_CC": "none"}
SAID = "no prebuilt binaries in this wheel"


@pytest.fixture(scope="module")
def checkout(tmp_path_factory):
    """A copy of the checkout's sources (what a fresh clone holds), one for the module: the
    second build meets the first one's build/ folder."""
    copy = tmp_path_factory.mktemp("clone") / "sma-fmu"
    shutil.copytree(REPO, copy, ignore=shutil.ignore_patterns(
        ".git", "build", "dist", "*.egg-info", "__pycache__", ".pytest_cache", "prebuilt_binaries",
        "prebuilt", "*.fmu", ".venv", "venv"))   # .gitignore's outputs
    return copy


def pip_wheel(source, out, **environment):
    """``pip wheel`` of ``source`` into ``out`` (verbose: the backend's lines); (wheel or None,
    the output). The PATH starts with this Python's bin/, as in an activated venv."""
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}",
           **environment}
    result = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-v", "--wheel-dir",
                             str(out), str(source)], capture_output=True, text=True, env=env,
                            timeout=3600)
    wheels = sorted(Path(out).glob("sma_fmu-*.whl"))
    return (wheels[0] if result.returncode == 0 and wheels else None), result.stdout + result.stderr


def _names(wheel):
    return set(zipfile.ZipFile(wheel).namelist())


def expected_binaries():
    """What the wheel's prebuilt folders hold: every model on every FMI 2.0 platform and on
    every FMI 3.0 one, the Python family's fronts, the C hosts, and their manifests."""
    names = {f"{PREBUILT}/{model}/{entry.fmi2}/{model}{entry.suffix}"
             for model in FMU_SCRIPTS for entry in fmi2_targets()}
    names |= {f"{PREBUILT}/{fmi3_key(model)}/{name}/{model}{entry.suffix}"
              for model in FMU_SCRIPTS for name, entry in TARGETS.items()}
    names |= {f"{PREBUILT}/front/linux64/front.so", f"{PREBUILT}/front/win64/front.dll",
              f"{PREBUILT}/manifest.json", f"{HOSTS}/manifest.json"}
    return names | {f"{HOSTS}/{name}" for name in HOST_PROGRAMS}


@pytest.mark.needs("gcc", "mingw-w64", "zig")
def test_with_the_compilers_the_wheel_holds_every_prebuilt_binary(checkout, tmp_path):
    kept = checkout / PREBUILT / "kept-by-hand.txt"   # a folder there before: put back after
    kept.parent.mkdir(parents=True)
    kept.write_text("an earlier writer's folder\n")
    wheel, output = pip_wheel(checkout, tmp_path)
    assert wheel is not None, output[-5000:]
    names = _names(wheel)
    prebuilt = {name for name in names if name.startswith((PREBUILT, HOSTS))}
    assert prebuilt == expected_binaries()
    assert "compiling the prebuilt binaries" in output and SAID not in output
    assert wheel.stat().st_size < 10_000_000
    with zipfile.ZipFile(wheel) as archive:   # the hosts stay executable
        assert all(archive.getinfo(f"{HOSTS}/{name}").external_attr >> 16 & 0o111 for name in HOST_PROGRAMS)
    assert sorted(p.name for p in (checkout / PREBUILT).iterdir()) == ["kept-by-hand.txt"]
    assert not (checkout / HOSTS).exists()


def test_without_compilers_the_wheel_compiles_where_it_runs_and_says_so(checkout, tmp_path):
    wheel, output = pip_wheel(checkout, tmp_path, **NO_COMPILERS)
    assert wheel is not None, output[-5000:]
    names = _names(wheel)
    assert not any(name.startswith((PREBUILT, HOSTS)) for name in names)   # not even build/'s
    # the sources sma-fmu build --native compiles, as a wheel built from the sdist always had
    assert {"sma_fmu/fmi/models/SmaActuator/SmaActuator.c", "sma_fmu/fmi/hosts/fmi_host.c",
            "sma_fmu/fmi/python_family/front/fmi2_exports.c",
            "sma_fmu/cosim/stroke_table.c"} <= names   # the masters' stroke table
    said = next(line for line in output.splitlines() if SAID in line)
    assert "no-such-cc" in said and "no-such-mingw-gcc" in said and "x86_64-darwin" in said
    assert "SMA_FMU_PREBUILT=require" in said


def test_require_fails_without_compilers(checkout, tmp_path):
    wheel, output = pip_wheel(checkout, tmp_path, SMA_FMU_PREBUILT="require", **NO_COMPILERS)
    assert wheel is None
    assert SAID in output and "(SMA_FMU_PREBUILT=require)" in output



def _zig_command_in_a_bare_python(path, **environment):
    """zig_command() as an isolated build's Python sees it: no ziglang module importable
    (no site-packages), this checkout's sma_fmu, PATH ``path``."""
    code = (f"import sys; sys.path.insert(0, {str(REPO)!r}); "
            "from sma_fmu.fmi.packaging.cross_build import zig_command; print(zig_command())")
    env = {"PATH": str(path), **environment}
    result = subprocess.run([sys.executable, "-S", "-c", code], capture_output=True, text=True, env=env)
    assert result.returncode == 0, result.stderr
    return result.stdout.strip()


def test_an_isolated_build_finds_zig_on_the_path(tmp_path):
    import ziglang   # the test extra's
    for program in ("python-zig", "zig"):
        (tmp_path / program).write_text("#!/bin/sh\nexit 0\n")
        (tmp_path / program).chmod(0o755)
    assert _zig_command_in_a_bare_python(tmp_path) == "['zig', 'cc']"   # zig first
    (tmp_path / "zig").unlink()
    # ziglang's script: the zig of the package its own Python imports (not the script, which
    # the isolated build's PYTHONPATH would keep from importing ziglang)
    (tmp_path / "python-zig").write_text(f"#!{sys.executable}\nimport ziglang\n")
    zig = str(Path(ziglang.__file__).parent / "zig")
    assert _zig_command_in_a_bare_python(tmp_path, PYTHONPATH=str(tmp_path)) == repr([zig, "cc"])
    (tmp_path / "python-zig").write_text("#!/bin/false\n")   # a script whose Python has no ziglang
    assert _zig_command_in_a_bare_python(tmp_path) == "None"
    assert _zig_command_in_a_bare_python(tmp_path, SMA_FMU_ZIG_CC="my-zig cc") == "['my-zig', 'cc']"
    assert _zig_command_in_a_bare_python(tmp_path, SMA_FMU_ZIG_CC="none") == "None"
    (tmp_path / "python-zig").unlink()
    assert _zig_command_in_a_bare_python(tmp_path) == "None"
