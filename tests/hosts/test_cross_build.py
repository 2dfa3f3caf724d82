"""The C family compiles for every platform of its table (sma_fmu/fmi/packaging/cross_build.py).

No C file of ours uses a name a C library defines as a macro (darwin's math.h defines DOMAIN,
SING, OVERFLOW, UNDERFLOW, TLOSS, PLOSS: a variable so named stopped the macOS build), and
SmaActuator's sources/ (the largest: the whole runtime) compile with ``-Werror`` under
``zig cc`` for each target, into a binary of the target's format and architecture.
"""
import re
import zipfile
from pathlib import Path

import pytest

from system_needs import need
from sma_fmu.fmi.packaging.cross_build import TARGETS, compile_shared, target
from sma_fmu.fmi.packaging.platforms import binary_architecture

FMI = Path(__file__).parents[2] / "sma_fmu" / "fmi"
LIBC_MACROS = ("DOMAIN", "SING", "OVERFLOW", "UNDERFLOW", "TLOSS", "PLOSS")


def test_no_c_file_uses_a_libc_macro_name():
    files = sorted(FMI.rglob("*.c")) + sorted(FMI.rglob("*.h"))
    assert len(files) > 50
    pattern = re.compile(r"\b(" + "|".join(LIBC_MACROS) + r")\b")
    found = [f"{path.relative_to(FMI)}:{number}: {line.strip()}"
             for path in files if "fmi2Function" not in path.name
             for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
             if pattern.search(re.sub(r'"[^"]*"|/\*.*?\*/|//.*', "", line))]
    assert found == []


def test_the_table_names_fmi2_and_fmi3_platforms():
    assert target("linux64") is TARGETS["x86_64-linux"]
    assert [t.fmi2 for t in TARGETS.values() if t.fmi2] == ["linux64", "win64", "darwin64", "win32"]
    assert set(TARGETS) >= {"x86_64-linux", "aarch64-linux", "x86_64-windows", "x86_64-darwin",
                            "aarch64-darwin"}
    with pytest.raises(KeyError, match="darwin64"):
        target("linux32")


@pytest.fixture(scope="module")
def actuator_sources(native_fmus, tmp_path_factory):
    folder = tmp_path_factory.mktemp("actuator")
    with zipfile.ZipFile(native_fmus["SmaActuator"]) as archive:
        archive.extractall(folder)
    return folder / "sources"


_FORMATS = {".so": b"\x7fELF", ".dll": b"MZ", ".dylib": b"\xcf\xfa\xed\xfe"}
_ARCHITECTURES = {"x86_64": "x86-64", "aarch64": "aarch64", "x86": "x86"}


@pytest.mark.needs("gcc", "zig")
@pytest.mark.parametrize("name", ["x86_64-darwin", "aarch64-darwin", "aarch64-linux", "x86-windows"])
def test_sources_compile_with_werror_under_zig(actuator_sources, tmp_path, name):
    need("zig")
    entry = TARGETS[name]
    output = tmp_path / f"SmaActuator{entry.suffix}"
    assert compile_shared(entry, actuator_sources, output, prefer_zig=True) is None
    data = output.read_bytes()
    assert data.startswith(_FORMATS[entry.suffix])
    assert binary_architecture(data) == _ARCHITECTURES[name.split("-")[0]]
