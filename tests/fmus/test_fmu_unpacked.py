"""One unpacked folder per FMU file per process (sma_fmu.fmi.driving.unpacked), shared by FmuInstance."""
import os
import shutil
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

from sma_fmu.fmi.driving import unpacked
from sma_fmu.fmi.driving.instance import FmuInstance
from system_needs import needs

PREFIX = "sma_fmu_unpacked_"


def _resources_on_path(folder):
    resources = str(Path(folder) / "resources")
    return [entry for entry in sys.path if entry.rstrip("/") == resources]


def test_a_second_instance_reuses_the_folder_and_closing_keeps_it(fmus):
    with FmuInstance(fmus["SmaActuator"], "first", {"load": 0.05}) as first:
        folder = first._unzipped
        marker = Path(folder) / "marker.txt"
        marker.write_text("written after unpacking")
        first.step(0.0, 1e-3)
    assert Path(folder).is_dir() and marker.is_file()  # close() leaves it for the next one
    with FmuInstance(fmus["SmaActuator"], "second", {"load": 0.05}) as second:
        assert second._unzipped == folder
        second.step(0.0, 1e-3)
        assert second.get_real(("T",))[0] > 0.0
    assert marker.read_text() == "written after unpacking"  # not unpacked again


def test_instances_alive_together_share_the_folder_and_close_in_any_order(fmus, params):
    from sma_fmu.runtime.plant import PlantStepper
    loads = [0.01, 0.1, 0.25]
    instances = [FmuInstance(fmus["SmaActuator"], f"p{k}", {"load": f}) for k, f in enumerate(loads)]
    libraries = [PlantStepper(params, load=f) for f in loads]
    try:
        assert len({fmu._unzipped for fmu in instances}) == 1
        instances[1].close()  # one closed (its library unloaded once) while the others step on
        for k in range(200):
            for index in (0, 2):
                instances[index].set_real(("P_in", "load"), (0.8, loads[index]))
                instances[index].step(k * 1e-3, 1e-3)
                libraries[index].step(0.8, loads[index], 1e-3)
        again = FmuInstance(fmus["SmaActuator"], "again", {"load": loads[1]})  # loaded again
        instances[1] = again
        for k in range(200):
            again.set_real(("P_in", "load"), (0.8, loads[1]))
            again.step(k * 1e-3, 1e-3)
            libraries[1].step(0.8, loads[1], 1e-3)
        for fmu, library in zip(instances, libraries):
            assert fmu.get_real(("T", "R")) == [library.outputs.T, library.outputs.R]
    finally:
        for fmu in instances:
            fmu.close()


def test_a_rebuilt_file_at_the_same_path_is_unpacked_again(fmus, tmp_path):
    path = tmp_path / "Plant.fmu"
    shutil.copyfile(fmus["SmaActuator"], path)
    with FmuInstance(path, "old") as old:
        old_folder = old._unzipped
        shutil.copyfile(fmus["SmaFeedforward"], path)  # another FMU at the same path, in use
        os.utime(path, ns=(1, 1))  # a different modification time even on a coarse clock
        with FmuInstance(path, "new") as new:
            new_folder = new._unzipped
            assert new_folder != old_folder
            assert "P_ff" in new.variables and "P_ff" not in old.variables
            assert Path(old_folder).is_dir()  # still in use by "old"
            old.step(0.0, 1e-3)
    assert not Path(old_folder).exists()  # the last user of an outdated folder removes it
    assert Path(new_folder).is_dir()
    assert unpacked.folders()[str(path.resolve())] == new_folder


def test_closing_leaves_no_resources_entry_on_sys_path(fmus):
    instances = [FmuInstance(fmus["SmaFeedforward"], f"ff{k}") for k in range(2)]
    folder = instances[0]._unzipped
    for fmu in instances:
        fmu.close()
        assert _resources_on_path(folder) == []
    sys.path.append(str(Path(folder) / "resources"))  # as pythonfmu's own code would leave it
    FmuInstance(fmus["SmaFeedforward"], "ff2").close()
    assert _resources_on_path(folder) == []


def test_threads_acquiring_at_once_get_one_folder(fmus, tmp_path):
    path = tmp_path / "Threads.fmu"
    shutil.copyfile(fmus["SmaPwmDriver"], path)
    start, got = threading.Barrier(4), []

    def worker():
        start.wait()
        got.append(unpacked.acquire(path))

    threads = [threading.Thread(target=worker) for _ in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert len(got) == 4 and len({id(u) for u in got}) == 1 and got[0].users == 4
    for one in got:
        unpacked.release(one)
    assert got[0].users == 0 and Path(got[0].folder).is_dir()  # current: kept for the next
    assert unpacked.folders()[str(path.resolve())] == got[0].folder


CHILD = """
import sys
from sma_fmu.fmi.driving.instance import FmuInstance
for k in range(3):
    with FmuInstance(sys.argv[1], f"child{k}", {"load": 0.05}) as fmu:
        fmu.step(0.0, 1e-3)
print(fmu._unzipped)
"""


def _ours(root):
    return {entry.name for entry in Path(root).iterdir() if entry.name.startswith(PREFIX)}


def test_a_process_removes_its_folders_when_it_exits(fmus, tmp_path):
    environment = {**os.environ, "TMPDIR": str(tmp_path)}
    result = subprocess.run([sys.executable, "-c", CHILD, str(fmus["SmaActuator"])],
                            env=environment, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-2000:]
    folder = Path(result.stdout.strip().splitlines()[-1])
    assert folder.parent == tmp_path and folder.name.startswith(PREFIX)  # it did unpack there
    assert _ours(tmp_path) == set()


FORKED = """
import multiprocessing, sys, tempfile
from pathlib import Path
from sma_fmu.fmi.driving.instance import FmuInstance

def child(path, fresh):
    with FmuInstance(path, "in-child") as fmu:  # the parent's folder
        fmu.step(0.0, 1e-3)
    with FmuInstance(fresh, "fresh-in-child") as fmu:  # a folder of the child's own
        fmu.step(0.0, 1e-3)
        print("child", fmu._unzipped, flush=True)

if __name__ == "__main__":
    path, fresh = sys.argv[1], sys.argv[2]
    parent = FmuInstance(path, "in-parent")
    process = multiprocessing.get_context("fork").Process(target=child, args=(path, fresh))
    process.start(); process.join()
    assert process.exitcode == 0
    left = sorted(p.name for p in Path(tempfile.gettempdir()).iterdir())
    print("after-child", " ".join(left), flush=True)
    assert Path(parent._unzipped).is_dir()  # the child did not remove the parent's folder
    parent.step(0.0, 1e-3)
    parent.close()
    print("parent", parent._unzipped, flush=True)
"""


def test_a_forked_child_removes_only_its_own_folders(fmus, tmp_path):
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    environment = {**os.environ, "TMPDIR": str(scratch)}
    result = subprocess.run([sys.executable, "-c", FORKED, str(fmus["SmaActuator"]),
                             str(fmus["SmaFeedforward"])],
                            env=environment, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-3000:]
    lines = dict(line.split(" ", 1) for line in result.stdout.strip().splitlines())
    parent, child = Path(lines["parent"]), Path(lines["child"])
    assert parent.parent == scratch and child.parent == scratch and parent != child
    assert lines["after-child"].split() == [parent.name]  # the child's own one removed at its exit
    assert _ours(scratch) == set()                        # and the parent's at the parent's exit


def test_unpack_each_gives_every_instance_its_own_folder(fmus, tmp_path, monkeypatch):
    monkeypatch.setenv(unpacked.UNPACK_EACH_VARIABLE, "1")
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    first = FmuInstance(fmus["SmaFeedforward"], "each1")
    second = FmuInstance(fmus["SmaFeedforward"], "each2")
    try:
        assert first._unzipped != second._unzipped
        assert len(_ours(tmp_path)) == 2
    finally:
        first.close()
        second.close()
    assert _ours(tmp_path) == set()  # removed at close, as before the cache


KILLED = """
import os, signal, sys
from sma_fmu.fmi.driving import unpacked
print(unpacked.acquire(sys.argv[1]).folder, flush=True)
os.kill(os.getpid(), signal.SIGKILL)   # no exit handler runs: the folder stays behind
"""

WAITING = """
import sys
from sma_fmu.fmi.driving import unpacked
print(unpacked.acquire(sys.argv[1]).folder, flush=True)
sys.stdin.read()   # alive until its stdin closes
"""

SWEEPING = """
import sys
from sma_fmu.fmi.driving import unpacked
print(unpacked.acquire(sys.argv[1]).folder, flush=True)   # the first unpack sweeps
"""


def test_the_folders_of_a_killed_process_are_removed_by_the_next_one(fmus, tmp_path):
    """A killed process leaves its folder; the next process to unpack removes it, but not
    the folder of a process still alive; each removes its own at its exit."""
    environment = {**os.environ, "TMPDIR": str(tmp_path)}
    path = str(fmus["SmaActuator"])
    killed = subprocess.run([sys.executable, "-c", KILLED, path], env=environment,
                            capture_output=True, text=True, timeout=300)
    assert killed.returncode == -9, killed.stderr[-2000:]
    stale = Path(killed.stdout.strip())
    assert stale.parent == tmp_path and (stale / "modelDescription.xml").is_file()
    waiting = subprocess.Popen([sys.executable, "-c", WAITING, path], env=environment,
                               stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        alive = Path(waiting.stdout.readline().strip())
        assert alive.is_dir() and alive != stale
        sweeping = subprocess.run([sys.executable, "-c", SWEEPING, path], env=environment,
                                  capture_output=True, text=True, timeout=300)
        assert sweeping.returncode == 0, sweeping.stderr[-2000:]
        assert not stale.exists()                     # the killed process's: removed
        assert alive.is_dir()                         # the living one's: kept
        assert _ours(tmp_path) == {alive.name}        # the sweeper's own: removed at its exit
    finally:
        waiting.stdin.close()
        waiting.wait(timeout=300)
    assert _ours(tmp_path) == set()


def test_remove_stale_names_what_it_removed_and_keeps_its_own(fmus, tmp_path):
    environment = {**os.environ, "TMPDIR": str(tmp_path)}
    killed = subprocess.run([sys.executable, "-c", KILLED, str(fmus["SmaFeedforward"])],
                            env=environment, capture_output=True, text=True, timeout=300)
    stale = Path(killed.stdout.strip())
    own = tmp_path / f"{PREFIX}{os.getpid()}_mine"
    own.mkdir()
    other = tmp_path / "sma_fmu_unpacked_not-a-pid"
    other.mkdir()
    assert unpacked.remove_stale(tmp_path) == [stale.name]
    assert own.is_dir() and other.is_dir() and not stale.exists()
    assert unpacked.remove_stale(tmp_path) == []


C_MASTER_RUN = """
import sys
from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios
from sma_fmu.systems.c_master import run_c_master
scenario = load_scenario(resolve_scenarios(["heavy-pi"])[0])
print(run_c_master(scenario, sys.argv[1]).data.size, flush=True)
"""


@needs("gcc")
def test_the_c_master_unpacks_per_process_and_removes_them_at_exit(native_fmus, tmp_path):
    environment = {**os.environ, "TMPDIR": str(tmp_path)}
    done = subprocess.run([sys.executable, "-c", C_MASTER_RUN, str(native_fmus["SmaActuator"].parent)],
                          env=environment, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip() == "30001"
    assert _ours(tmp_path) == set() and not (tmp_path / "sma-fmu-unpacked").exists()


def test_only_what_a_host_runs_is_unpacked_and_another_platform_is_added_later(native_fmus, tmp_path):
    """The model description, resources/ and this platform's binaries; not the sources, the
    documentation, extra/ or other platforms' binaries, which the archive holds. A win64 host
    (under wine) asking later gets win64's binaries in the same folder, byte for byte."""
    import zipfile

    import fmpy

    path = tmp_path / "Plant.fmu"
    shutil.copyfile(native_fmus["SmaActuator"], path)
    with zipfile.ZipFile(path) as archive:
        names = [n for n in archive.namelist() if not n.endswith("/")]
        dll = archive.read("binaries/win64/SmaActuator.dll")
    for prefix in ("sources/", "documentation/", "extra/", "binaries/win64/", "binaries/darwin64/"):
        assert any(n.startswith(prefix) for n in names), prefix   # in the archive
    resources = {n for n in names if n.startswith("resources/")}
    first = unpacked.acquire(path)
    try:
        folder = Path(first.folder)
        got = {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()}
        assert resources and got == {"modelDescription.xml", f"binaries/{fmpy.platform}/SmaActuator.so",
                                     *resources}
        second = unpacked.acquire(path, unpacked.WIN64)
        try:
            assert second is first
            assert (folder / "binaries/win64/SmaActuator.dll").read_bytes() == dll
            assert not (folder / "binaries/darwin64").exists() and not (folder / "sources").exists()
        finally:
            unpacked.release(second)
    finally:
        unpacked.release(first)
