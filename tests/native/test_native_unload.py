"""Unloading a native FMU's library releases the ring of freed instances it keeps (issue 38,
F4): a C host that loads the binary, makes and frees instances, and unloads it, over and over,
keeps its resident memory flat. Before, 2,000 cycles of one instance grew it 1.5 -> 3.1 MB and
50 cycles of 1,000 instances 2.3 -> 40.7 MB (the ring, up to 1,024 freed instances of about
0.7 KiB, was never released)."""
import subprocess
import zipfile
from pathlib import Path

import pytest
from fmpy import read_model_description

pytestmark = pytest.mark.needs("gcc")

HOST = Path(__file__).parents[1] / "support" / "native_unload_host.c"


@pytest.fixture(scope="module")
def unload_run(native_fmus, tmp_path_factory):
    """run(warmup, cycles, instances) -> (kB after the warm-up, kB at the end)."""
    folder = tmp_path_factory.mktemp("unload")
    with zipfile.ZipFile(native_fmus["SmaActuator"]) as archive:
        archive.extractall(folder / "fmu")
    exe = folder / "host"
    subprocess.run(["gcc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-o", str(exe), str(HOST),
                    "-ldl"], check=True)
    guid = read_model_description(str(native_fmus["SmaActuator"])).guid
    binary = folder / "fmu" / "binaries" / "linux64" / "SmaActuator.so"
    uri = (folder / "fmu" / "resources").as_uri()

    def run(warmup, cycles, instances):
        result = subprocess.run([str(exe), str(binary), guid, uri, str(warmup), str(cycles),
                                 str(instances)], capture_output=True, text=True, timeout=600)
        assert result.returncode == 0, result.stderr
        before, after = map(int, result.stdout.split())
        return before, after
    return run


def test_two_thousand_load_unload_cycles_grow_memory_by_less_than_1_mb(unload_run):
    before, after = unload_run(100, 2000, 1)
    assert after - before < 1024, (before, after)


def test_cycles_of_a_thousand_instances_keep_memory_flat(unload_run):
    """Each cycle fills the ring (1,000 freed instances, ~0.7 MB); unloading empties it, so
    the next cycle reuses that memory instead of adding its own."""
    before, after = unload_run(5, 45, 1000)
    assert after - before < 2048, (before, after)
