"""Ctrl-C: one line ``sma-fmu: interrupted``, exit status 130, no traceback, nothing left
behind, whenever it comes, in both masters, the in-process pythonfmu FMUs and the builds;
once the results are in place (too late to undo), the line names them as written in full.

The suite sends a seeded sample of SIGINTs (a few seconds each); tests/cli/interrupts_check.py
sends 50 by hand. The unit tests below pin the rules of sma_fmu/console/interrupts.py."""
import json
import random
import shutil
import signal
import sys
import tempfile
from pathlib import Path

import pytest

from interrupting import interrupt, interrupt_in_time
from sma_fmu.console import interrupts
from sma_fmu.cli import main
from sma_fmu.console.interrupts import run_child
from sma_fmu.files import output_folder
from sma_fmu.files.package_data import shipped_file
from sma_fmu.fmi.packaging.pythonfmu_build import _renamer, code_stamp

# command -> (its arguments in the work folder, the latest moment of the interrupt [s]): each
# ends well after that on this project's CI machine, so the interrupt lands inside its work
COMMANDS = {
    "run paper (fmpy master)": (["run", "paper", "--fmus", "fmus", "--out", "results"], 6.0),
    "run paper (C master)": (["run", "paper", "--fmus", "native", "--master", "c", "--out", "rc"], 2.5),
    "build": (["build", "--out", "fmus-new"], 8.0),
    "build --native": (["build", "--native", "--out", "native-new"], 8.0),
    "fit isobaric": (["fit", "isobaric", "isobaric.csv", "--out", "fit"], 4.0),
}
SAMPLE = 7   # interrupts in the suite: every command once, two more drawn (seeded)
EARLIEST_S = 0.3   # the earliest interrupt [s]: a command that ends first is retried earlier


def _plan(seed=48):
    rng = random.Random(seed)
    names = list(COMMANDS) + rng.sample(list(COMMANDS), SAMPLE - len(COMMANDS))
    return [(name, round(rng.uniform(EARLIEST_S, COMMANDS[name][1]), 2)) for name in names]


@pytest.fixture(scope="module")
def work(tmp_path_factory, fmus, native_fmus):
    """A folder holding the inputs: the FMUs of both families and the shipped isobaric file."""
    folder = tmp_path_factory.mktemp("interrupts")
    for name, paths in (("fmus", fmus), ("native", native_fmus)):
        (folder / name).mkdir()
        for path in paths.values():
            shutil.copyfile(path, folder / name / path.name)
    shutil.copyfile(shipped_file("examples", "isobaric.csv"), folder / "isobaric.csv")
    return folder


@pytest.mark.needs("gcc")
@pytest.mark.parametrize("name, after_s", _plan())
def test_a_ctrl_c_ends_with_one_line_and_leaves_nothing(work, name, after_s):
    # a quicker machine that finished first is interrupted earlier (the moment is a sample,
    # the rule is the same whenever the interrupt lands)
    result = interrupt_in_time(COMMANDS[name][0], work, after_s, EARLIEST_S)
    assert result.status != 0, f"{name} ended before the interrupt at {result.after_s} s"
    assert result.problems() == [], (name, after_s, result.stderr[-2000:])


def test_a_ctrl_c_while_the_results_move_into_place_names_them_written_in_full(
        tmp_path, monkeypatch, capsys):
    """The moment CI once hit (``run paper`` with the C master, 1.87 s): the move is not cut,
    so the results are whole; the line says so instead of claiming nothing was written."""
    def commit_then_ctrl_c(*arguments):
        commit(*arguments)
        signal.raise_signal(signal.SIGINT)
    commit = output_folder._commit
    monkeypatch.setattr(output_folder, "_commit", commit_then_ctrl_c)
    out = tmp_path / "examples"
    assert main(["examples", "--out", str(out)]) == 130
    assert capsys.readouterr().err.strip().splitlines()[-1] == \
        f"sma-fmu: interrupted after writing {out} in full"
    listed = json.loads((out / output_folder.MARKER).read_text(encoding="utf-8"))["entries"]
    assert sorted(listed) == sorted(e.name for e in out.iterdir() if e.name != output_folder.MARKER)
    assert "scenarios" in listed and sorted(p.name for p in tmp_path.iterdir()) == ["examples"]


def test_only_results_still_there_count_as_placed_not_a_sweeps_parts(tmp_path):
    with interrupts.handle_interrupts():
        output_folder.write_file(tmp_path / "result.ssp", b"whole")
        output_folder.write_file(tmp_path / "part-1.parquet", b"kept for a resume", final=False)
        with output_folder.staged_folder(tmp_path / "out") as stage:
            (stage / "a.csv").write_text("1")
        assert interrupts.outputs_placed() == [str(tmp_path / "result.ssp"), str(tmp_path / "out")]
        shutil.rmtree(tmp_path / "out")   # an intermediate one, removed: not named
        assert interrupts.outputs_placed() == [str(tmp_path / "result.ssp")]
    with interrupts.handle_interrupts():   # a new command starts with none
        assert interrupts.outputs_placed() == []


@pytest.mark.parametrize("once, after_s, path", [("tmp/dask-sweep-*", 0.0, "batch"),
                                                  ("sweep/study.json", 0.0, "batch"),
                                                  ("sweep/runs/part-*", 0.0, "batch"),
                                                  ("sweep/runs/part-*", 0.0, "fmu")],
                         ids=["cluster starting", "cluster started", "runs under way",
                              "runs under way, --fmus"])
def test_a_ctrl_c_to_a_sweep_reaches_its_dask_workers_through_it_alone(tmp_path, native_fmus,
                                                                       once, after_s, path):
    """A sweep keeps the runs it finished (study.json, runs/) and says one line. Its Dask
    worker processes, in the terminal's process group, once printed their KeyboardInterrupts
    and Dask at exit "AssertionError: Status.init" (a cluster cut mid-start); mid-run they
    took their task to its end (seconds). Ended at once, the FMUs they unpacked go too."""
    arguments = ["sweep", shipped_file("examples", "gain-grid.toml"), "--out", "sweep",
                 "--workers", "2"]
    if path == "fmu":
        (tmp_path / "native").mkdir()
        for fmu in native_fmus.values():
            shutil.copyfile(fmu, tmp_path / "native" / fmu.name)
        arguments += ["--fmus", "native"]
    result = interrupt(arguments, tmp_path, after_s, once=once)
    assert result.status == 130, (result.status, result.stderr[-2000:])
    kept = [entry for entry in result.new_entries if entry not in ("sweep", "sweep/study.json")
            and not (entry == "sweep/runs" or entry.startswith("sweep/runs/part-"))]
    problems = [p for p in result.problems() if not p.startswith("left behind")]
    assert problems == [] and kept == [], (problems, kept, result.stderr[-2000:])


def _frame_of(module_name):
    """A frame whose module is ``module_name`` (its code run in such a namespace)."""
    namespace = {"__name__": module_name, "sys": sys}
    exec("def probe():\n    return sys._getframe()\n", namespace)  # noqa: S102 - a fixed text
    return namespace["probe"]()


def test_code_of_a_pythonfmu_fmu_is_told_from_the_master():
    stamp = code_stamp()
    names, _ = _renamer("sma_actuator", stamp)
    for module in (f"sma_actuator_{stamp}", f"{names['sma_fmu.runtime']}.plant",
                   f"{names['sma_fmu.fmi.python_family.slave_support']}.guards",
                   "pythonfmu.fmi2slave"):
        assert interrupts.in_fmu_code(_frame_of(module)), module
    for module in ("sma_fmu.cosim.master", "pythonfmu.builder", "numpy.core", "__main__"):
        assert not interrupts.in_fmu_code(_frame_of(module)), module


def test_without_the_handler_nothing_changes():
    with interrupts.deferred():   # not installed: a no-op
        pass
    assert not interrupts.seen()


def test_a_deferred_section_gets_its_interrupt_at_its_end():
    finished = []
    with interrupts.handle_interrupts():
        with pytest.raises(KeyboardInterrupt):
            with interrupts.deferred():
                signal.raise_signal(signal.SIGINT)
                finished.append("the section ran to its end")
        assert interrupts.seen() and finished
        signal.raise_signal(signal.SIGINT)   # after the first: ignored while ending
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_a_ctrl_c_inside_fmu_code_comes_when_the_fmu_call_returns():
    """pythonfmu would turn a KeyboardInterrupt in its slave into fmi2Fatal: the slave's step
    runs to its end, and the interrupt comes in the caller's next line."""
    namespace = {"__name__": f"sma_actuator_{code_stamp()}", "signal": signal}
    exec("def step(log):\n"  # noqa: S102 - a fixed text, a slave step's stand-in module
         "    signal.raise_signal(signal.SIGINT)\n"
         "    log.append('the step ran to its end')\n"
         "    return True\n", namespace)
    log = []
    with interrupts.handle_interrupts():
        with pytest.raises(KeyboardInterrupt):
            namespace["step"](log)
            log.append("the master went on")   # never: the interrupt comes here
    assert log == ["the step ran to its end"] and sys.gettrace() is None


def test_a_temporary_folder_being_removed_is_removed_whole_before_the_interrupt(monkeypatch):
    """pythonfmu's build folder (a TemporaryDirectory) once stayed behind, half removed: the
    Ctrl-C came inside its removal."""
    def rmtree_after_a_ctrl_c(*arguments, **options):
        signal.raise_signal(signal.SIGINT)
        rmtree(*arguments, **options)

    def build(made):
        with tempfile.TemporaryDirectory(prefix="removed-whole-") as folder:
            made.append(Path(folder))
            (made[0] / "a.txt").write_text("a")
            monkeypatch.setattr(tempfile._shutil, "rmtree", rmtree_after_a_ctrl_c)
        made.append("the removal ended")   # the interrupt comes here, in its caller's next line

    rmtree, made = tempfile._shutil.rmtree, []
    with interrupts.handle_interrupts():
        with pytest.raises(KeyboardInterrupt):
            build(made)
    monkeypatch.undo()
    assert made == [made[0]] and not made[0].exists()


def test_a_process_about_to_exit_ignores_a_late_ctrl_c():
    """The ``sma-fmu`` process (``then_ignore``): once the command is over, SIGINT is ignored,
    so a Ctrl-C during the interpreter's shutdown neither kills it by the signal nor prints a
    traceback; in-process callers get the handler they had back."""
    before = signal.getsignal(signal.SIGINT)
    try:
        with interrupts.handle_interrupts():
            pass
        assert signal.getsignal(signal.SIGINT) is before
        with interrupts.handle_interrupts(then_ignore=True):
            assert signal.getsignal(signal.SIGINT) not in (before, signal.SIG_IGN)
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, before)


def test_a_compiler_gets_a_temporary_folder_of_its_own_removed_after_it(tmp_path, monkeypatch):
    """A gcc ended by a Ctrl-C may leave its cc*.s behind (its as still holds it): the
    compilers run with TMPDIR in a folder of their own, which goes when they end."""
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    leave = ("import os, tempfile; folder = tempfile.gettempdir(); "
             "open(os.path.join(folder, 'ccLEFT.s'), 'w').close(); print(folder)")
    result = run_child([sys.executable, "-c", leave], text=True, timeout=60, own_temp=True)
    folder = result.stdout.strip()
    assert result.returncode == 0 and folder and folder != str(tmp_path)
    assert not (tmp_path / "ccLEFT.s").exists() and not Path(folder).exists()
