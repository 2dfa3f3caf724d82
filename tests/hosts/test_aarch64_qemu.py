"""aarch64-linux: SmaActuator's sources cross-built with zig cc, stepped under qemu-aarch64 by
the plain C host (fmi_host.c) cross-built the same way, against the linux64 binary that
``sma-fmu build --native`` ships, stepped by the gcc-built host, on the same random walks.

The contract (docs/fmus.md, "Platforms"): our code contracts no FMA, so what differs is
the C library's exp/log/pow (glibc picks FMA variants on x86-64 CPUs that have it, aarch64
has its own): outputs agree to TOLERANCE relative to each output's scale over the walk,
not bit for bit. The largest difference found is printed (pytest -s).
"""
import random
import shutil
import zipfile

import pytest
from fmpy import read_model_description

from fmi_host import FmiHost
from fmu_signals import plant_walk
from system_needs import AARCH64_SYSROOT, need
from sma_fmu.fmi.packaging.cross_build import TARGETS, compile_host_for, compile_shared

pytestmark = pytest.mark.needs("gcc", "zig", "qemu-user")
TOLERANCE = 1e-12
OUTPUTS = ("R", "T", "x", "xi_P", "xi_M", "xi_F", "P")
STEPS = 2000


@pytest.fixture(scope="module")
def aarch64(native_fmus, tmp_path_factory):
    """(folder: the unpacked FMU with binaries/aarch64-linux/, the aarch64 fmi_host)."""
    need("gcc", "zig", "qemu-user")
    folder = tmp_path_factory.mktemp("actuator")
    with zipfile.ZipFile(native_fmus["SmaActuator"]) as archive:
        archive.extractall(folder)
    (folder / "binaries" / "linux64" / "SmaActuator.so").chmod(0o755)
    entry = TARGETS["aarch64-linux"]
    binary = folder / "binaries" / entry.tuple / "SmaActuator.so"
    binary.parent.mkdir(parents=True)
    assert compile_shared(entry, folder / "sources", binary) is None
    host = tmp_path_factory.mktemp("host") / "fmi_host"
    assert compile_host_for(entry, "fmi_host", host) is None
    return folder, host


def _walk(rng):
    """The plant's random walk (nested reversals, load changes): (P_in, load) per step."""
    return [(step["P_in"], step["load"]) for step in plant_walk(rng, STEPS)]


def _run(host, folder, inputs, mode):
    """[[outputs] per step] of SmaActuator stepped by ``host`` (hysteresis_mode ``mode``)."""
    refs = {v.name: v.valueReference for v in
            read_model_description(str(folder / "modelDescription.xml")).modelVariables}
    outputs = " ".join(str(refs[name]) for name in OUTPUTS)
    rows = []
    with host:
        assert host.call(f"instantiate 0 {b'walk'.hex()} ok ok 0").status == 0
        assert host.call(f"setint 0 1 {refs['hysteresis_mode']} {mode}").status == 0
        for command in ("setup 0 0 -", "enter 0", "exit 0"):
            assert host.call(command).status == 0, command
        for k, (power, load) in enumerate(inputs):
            assert host.call(f"setreal 0 2 {refs['P_in']} {power!r} {refs['load']} {load!r}").status == 0
            assert host.call(f"step 0 {k * 1e-3!r} 0.001").status <= 1
            reply = host.call(f"getreal 0 {len(OUTPUTS)} {outputs}")
            rows.append([float(value) for value in reply.values])
    return rows


@pytest.mark.parametrize("mode", [1, 2])
def test_aarch64_under_qemu_equals_x86_64(aarch64, fmi_host_exe, mode):
    folder, host = aarch64
    inputs = _walk(random.Random(40 + mode))
    native = _run(FmiHost(fmi_host_exe, folder), folder, inputs, mode)
    emulated = _run(FmiHost(host, folder, runner=(shutil.which("qemu-aarch64"), "-L", AARCH64_SYSROOT)),
                    folder, inputs, mode)
    assert len(native) == len(emulated) == STEPS
    worst, unequal = {}, 0
    for column, name in enumerate(OUTPUTS):
        scale = max(abs(row[column]) for row in native) or 1.0
        differences = [abs(a[column] - b[column]) / scale for a, b in zip(native, emulated)]
        unequal += sum(d != 0.0 for d in differences)
        worst[name] = max(differences)
    print(f"\naarch64-linux (qemu) vs x86_64-linux, hysteresis_mode {mode}, {STEPS} steps: "
          f"{unequal} of {STEPS * len(OUTPUTS)} values differ; largest relative to scale: "
          + ", ".join(f"{name} {value:.1e}" for name, value in worst.items()))
    assert max(worst.values()) <= TOLERANCE, worst
