"""The C family built with AddressSanitizer (leaks included) and UndefinedBehaviorSanitizer
stays clean through the cases of issue 38: every corruption of a saved state of the five FMUs
(tests/native/test_state_integrity.py), the start-values documents and non-regular files
(tests/native/test_start_values_files.py), non-finite parameters, a foreign resources folder, and
load/unload cycles. The binaries and the plain C host (sma_fmu/fmi/hosts/fmi_host.c) are
built here with -fsanitize=address,undefined; any report ends the host with a non-zero
status (UBSan does not recover), which the test shows with the host's stderr."""
import os
import shutil
import subprocess
from pathlib import Path

import pytest
from fmpy import read_model_description

from sma_fmu.fmi.c_common import include_flags

import test_start_values_files as documents
from fmi_host import FmiHost, unpack
from test_state_integrity import DRIVE, _cases

pytestmark = pytest.mark.needs("gcc")

SANITIZE = ["-fsanitize=address,undefined", "-fno-sanitize-recover=undefined",
            "-fno-omit-frame-pointer", "-g", "-O1"]
ENV = dict(os.environ, ASAN_OPTIONS="detect_leaks=1", UBSAN_OPTIONS="print_stacktrace=1")
HOSTS = Path(__file__).parents[2] / "sma_fmu" / "fmi" / "hosts"


@pytest.fixture(scope="module")
def sanitized(native_fmus, tmp_path_factory):
    """(fmi_host executable, {model: unpacked folder with a sanitized linux64 binary})."""
    from sma_fmu.fmi.packaging.c_family_build import FLAGS
    root = tmp_path_factory.mktemp("sanitized")
    folders = {}
    for model, fmu in native_fmus.items():
        folder = unpack(fmu, root / model)
        sources = sorted(str(p) for p in (folder / "sources").glob("*.c"))
        subprocess.run(["gcc", *[f for f in FLAGS if f != "-O2"], *SANITIZE, "-fPIC", "-I",
                        str(folder / "sources"), "-o",
                        str(folder / "binaries" / "linux64" / f"{model}.so"), *sources, "-lm"],
                       check=True)
        folders[model] = folder
    host = root / "fmi_host"
    subprocess.run(["gcc", "-std=c11", *SANITIZE, *include_flags(HOSTS), "-o", str(host),
                    str(HOSTS / "fmi_host.c"), "-ldl"], check=True)
    return host, folders


def _closed_clean(host):
    code = host.close()
    assert code == 0, host.process.stderr.read()[-3000:] if not host.process.stderr.closed else code


@pytest.mark.parametrize("model", sorted(DRIVE))
def test_corrupted_states_under_sanitizers(sanitized, model):
    exe, folders = sanitized
    refs = {v.name: v.valueReference for v in
            read_model_description(str(folders[model] / "modelDescription.xml")).modelVariables}
    host = FmiHost(exe, folders[model], env=ENV)
    for command in ("instantiate 0 6131 ok ok 0", "setup 0 0 -", "enter 0", "exit 0"):
        assert host.call(command).status == 0
    name, values = DRIVE[model]
    for k in range(30):
        if name:
            host.call(f"setreal 0 1 {refs[name]} {values[k // 10]!r}")
        assert host.call(f"step 0 {k * 1e-3!r} 0.001").status <= 1
    assert host.call("getstate 0 0").status == 0
    blob = bytes.fromhex(host.call("serialize 0 0").values[0])
    statuses = {host.call(f"deserialize 0 1 {bad.hex() or '_'}").status for _, bad in _cases(blob)}
    assert statuses == {3}
    assert host.call(f"deserialize 0 1 {blob.hex()}").status == 0
    assert host.call("setstate 0 1").status == 0
    _closed_clean(host)


def test_start_values_parameters_and_resources_under_sanitizers(sanitized):
    exe, folders = sanitized
    folder = folders["SmaActuator"]
    target = folder / "resources" / "start_values.json"
    for case, data in documents.DOCUMENTS.items():
        target.write_bytes(data)
        host = FmiHost(exe, folder, env=ENV)
        if host.call("instantiate 0 6131 ok ok 0").status == 0:
            for command in ("setup 0 0 -", "enter 0", "exit 0", "step 0 0 0.001"):
                host.call(command)
        _closed_clean(host)
    target.unlink()
    for kind in ("fifo", "folder", "dev-zero"):
        documents._special(kind)(folder / "resources")
        host = FmiHost(exe, folder, env=ENV)
        assert host.call("instantiate 0 6131 ok ok 0").status != 0
        _closed_clean(host)
        shutil.rmtree(target) if target.is_dir() else target.unlink()
    vr = {v.name: v.valueReference for v in
          read_model_description(str(folder / "modelDescription.xml")).modelVariables}
    for value in ("nan", "inf", "-inf"):
        host = FmiHost(exe, folder, env=ENV)
        for command in ("instantiate 0 6131 ok ok 0", "setup 0 0 -", "enter 0",
                        f"setreal 0 1 {vr['stress_max']} {value}"):
            assert host.call(command).status == 0
        assert host.call("exit 0").status == 3
        _closed_clean(host)
    host = FmiHost(exe, folder, env=ENV)
    assert host.call(f"instantiate 0 6131 {'file:///tmp'.encode().hex()} ok 0").status != 0
    _closed_clean(host)


def test_load_unload_cycles_under_sanitizers(sanitized, tmp_path):
    exe, folders = sanitized
    host = tmp_path / "unload_host"
    subprocess.run(["gcc", "-std=c99", *SANITIZE, "-o", str(host),
                    str(Path(__file__).parents[1] / "support" / "native_unload_host.c"), "-ldl"], check=True)
    folder = folders["SmaActuator"]
    guid = read_model_description(str(folder / "modelDescription.xml")).guid
    result = subprocess.run([str(host), str(folder / "binaries" / "linux64" / "SmaActuator.so"),
                             guid, (folder / "resources").as_uri(), "2", "50", "20"],
                            capture_output=True, text=True, env=ENV, timeout=600)
    assert result.returncode == 0, result.stderr[-3000:]


# ---- the FMI 3.0 front (issue 39) ----------------------------------------------------------
# The C family's fuzz cases (tests/support/fmi3_fuzz_cases.py: pinned refusals, random calls, the
# plant's arrays with wrong sizes) run through both fronts on binaries built from each FMU's
# sources/ with the sanitizers, in a child Python that preloads libasan. Python's own
# allocations (numpy, lxml, the interpreter) leak by LeakSanitizer's measure, so that run
# checks no leaks; the FMI 3.0 walk host (tests/support/fmi3_walk_host.c), a plain C host, runs each
# sanitized FMI 3.0 FMU with leak detection on.
SUPPORT = Path(__file__).parents[1] / "support"   # the tests' helpers
MODELS = ["SmaActuator", "SmaFeedforward", "SmaPiController", "SmaPwmDriver", "SmaScenarioSignals"]


def _sanitized_fmu(fmu, folder, platform, out):
    """``out``: ``fmu`` with its ``platform`` binary rebuilt from sources/ with SANITIZE."""
    import zipfile
    from sma_fmu.fmi.packaging.c_family_build import FLAGS
    with zipfile.ZipFile(fmu) as archive:
        archive.extractall(folder)
    model = fmu.stem
    sources = sorted(str(p) for p in (folder / "sources").glob("*.c"))
    subprocess.run(["gcc", *[f for f in FLAGS if f != "-O2"], *SANITIZE, "-fPIC", "-I",
                    str(folder / "sources"), "-o",
                    str(folder / "binaries" / platform / f"{model}.so"), *sources, "-lm"],
                   check=True)
    assert b"__asan_" in (folder / "binaries" / platform / f"{model}.so").read_bytes()
    out.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(out, "w") as archive:
        for path in sorted(folder.rglob("*")):
            if path.is_file():
                archive.write(path, path.relative_to(folder).as_posix())
    return folder


@pytest.fixture(scope="module")
def sanitized3(native_fmus, tmp_path_factory):
    """(FMI 2.0 FMU folder, FMI 3.0 FMU folder, {model: unpacked FMI 3.0 folder}), every
    linux binary built with the sanitizers."""
    from sma_fmu.fmi.packaging.fmi3_build import build_fmi3_fmus
    root = tmp_path_factory.mktemp("sanitized3")
    fmi3 = build_fmi3_fmus(root / "built3")
    unpacked = {}
    for model in MODELS:
        _sanitized_fmu(native_fmus[model], root / "u2" / model, "linux64", root / "v2" / f"{model}.fmu")
        unpacked[model] = _sanitized_fmu(fmi3[model], root / "u3" / model, "x86_64-linux",
                                         root / "v3" / f"{model}.fmu")
    return root / "v2", root / "v3", unpacked


def _reports(stderr):
    return [line for line in stderr.splitlines()
            if "AddressSanitizer" in line or "runtime error:" in line or "LeakSanitizer" in line]


def test_fuzz_cases_of_both_fronts_under_sanitizers(sanitized3):
    import sys
    fmi2, fmi3, _ = sanitized3
    libasan = subprocess.run(["gcc", "-print-file-name=libasan.so"], capture_output=True,
                             text=True, check=True).stdout.strip()
    env = dict(ENV, LD_PRELOAD=libasan, ASAN_OPTIONS="detect_leaks=0",
               PYTHONPATH=os.pathsep.join([str(SUPPORT), str(SUPPORT.parents[1])]))
    result = subprocess.run([sys.executable, str(SUPPORT / "fmi3_fuzz_cases.py"), str(fmi2),
                             str(fmi3), "150"], capture_output=True, text=True, env=env,
                            timeout=1200)
    assert result.returncode == 0 and not _reports(result.stderr), result.stderr[-3000:]
    lines = result.stdout.splitlines()
    assert [line.split(":")[0] for line in lines] == MODELS + ["arrays"], result.stdout
    assert lines[-1] == "arrays: 300 reads"


@pytest.mark.parametrize("model", MODELS)
def test_fmi3_walk_host_under_sanitizers_leaks_included(sanitized3, tmp_path, model):
    _, _, unpacked = sanitized3
    host = tmp_path / "walk"
    subprocess.run(["gcc", "-std=c99", *SANITIZE, *include_flags(), "-o", str(host),
                    str(SUPPORT / "fmi3_walk_host.c"), "-ldl", "-lm"], check=True)
    description = read_model_description(str(unpacked[model] / "modelDescription.xml"))
    floats = [v for v in description.modelVariables if v.type == "Float64"]
    inputs = [v.valueReference for v in floats if v.causality == "input"]
    outputs = [v.valueReference for v in floats if v.causality == "output" and not v.dimensions]
    result = subprocess.run([str(host), str(unpacked[model]), model,
                             description.instantiationToken, "500", "0.001",
                             str(inputs[0] if inputs else -1), *map(str, outputs)],
                            capture_output=True, text=True, env=ENV, timeout=600)
    assert result.returncode == 0 and not _reports(result.stderr), result.stderr[-3000:]
    assert len(result.stdout.splitlines()) == 500
