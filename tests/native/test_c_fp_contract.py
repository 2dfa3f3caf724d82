"""The C family's sources forbid fused multiply-add themselves (runtime/fp_contract.h), so a tool
that compiles sources/ with its own flags keeps the bit equality with the Python runtime.

gcc at -march=x86-64-v3 -ffp-contract=fast (what a tool on a modern x86-64, or any aarch64
compiler by default, does) emits FMA for a*b + c; the test compiles every C-family file so
and looks for an FMA instruction in the objects. It runs on any x86-64 machine: nothing is
executed, so the CPU need not have FMA.
"""
import platform
import shutil
import subprocess
from pathlib import Path

import pytest

from system_needs import need

import sma_fmu.fmi.c_family as c_family
from sma_fmu.fmi.packaging.parameter_table import generated_folder

ROOT = Path(c_family.__file__).parent
CONTRACTING = ("-std=c99", "-O2", "-march=x86-64-v3", "-ffp-contract=fast", "-c")


def _objects(folder, include_guard=True):
    need("gcc")
    sources = sorted(ROOT.glob("runtime/*.c"))
    includes = [f"-I{ROOT / 'runtime'}", f"-I{generated_folder()}"]
    objects = []
    for source in sources:
        target = folder / f"{source.stem}.o"
        command = ["gcc", *CONTRACTING, *includes, "-o", str(target), str(source)]
        if not include_guard:
            command.insert(1, "-DSMA_FP_CONTRACT_H")  # the header's pragma left out
        subprocess.run(command, check=True, capture_output=True, text=True)
        objects.append(target)
    return objects


def _fused(objects):
    dump = subprocess.run(["objdump", "-d", *map(str, objects)], check=True, capture_output=True,
                          text=True).stdout
    return sum(1 for line in dump.splitlines() if "vfmadd" in line or "vfmsub" in line
               or "vfnmadd" in line or "vfnmsub" in line)


@pytest.mark.skipif(platform.machine() != "x86_64", reason="x86-64 instruction names")
def test_no_fused_multiply_add_even_when_the_compiler_is_asked_for_it(tmp_path):
    assert shutil.which("objdump"), "objdump (binutils) comes with gcc"
    (tmp_path / "with").mkdir()
    (tmp_path / "without").mkdir()
    assert _fused(_objects(tmp_path / "with")) == 0
    # the same flags without the header's pragma do fuse: the check can fail
    assert _fused(_objects(tmp_path / "without", include_guard=False)) > 0
