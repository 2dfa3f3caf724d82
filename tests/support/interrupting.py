"""Ctrl-C at a random moment of a long command, as a terminal sends it, and what it left.

:func:`interrupt` starts ``sma-fmu ARGS`` in a folder of its own (its own process group, its
own temporary folder), waits ``after_s`` seconds and sends SIGINT to the whole group (what a
terminal's Ctrl-C does: compilers and C masters get it too), then checks the contract of
the command line: exit status 130, one line ``sma-fmu: interrupted`` on stderr, no traceback
anywhere, and no file or folder that was not there before (in the working folder and the
temporary folder; the compiler caches under the temporary folder are kept on purpose, and
left out). A Ctrl-C that came once the results were in place (the line ends ``after writing
OUT in full``) may leave OUT, if it holds exactly what its marker lists. Used by
tests/cli/test_interrupts.py and by hand by tests/cli/interrupts_check.py (50 of them).
"""
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from sma_fmu.files.output_folder import MARKER

__all__ = ["Interrupted", "interrupt", "sma_fmu_command", "tree"]

# caches under the temporary folder, kept across runs on purpose, each filled atomically: the
# C family's compiler cache, the C hosts (sma-fmu-<host>-<key>), zig's
_CACHE_PREFIXES = ("sma-fmu-", "zig")
_LINE = re.compile(r"sma-fmu: interrupted(?: after writing (.+) in full)?")


def sma_fmu_command():
    """The ``sma-fmu`` console script next to this Python, else ``python -m sma_fmu``-like."""
    script = Path(sys.executable).with_name("sma-fmu")
    return [str(script)] if script.is_file() else [sys.executable, "-c",
                                                   "import sys; from sma_fmu.cli import main; "
                                                   "sys.exit(main())"]


def tree(folder, leave_out=()):
    """The relative paths of everything under ``folder`` (a set); folders whose names start
    with one of ``leave_out`` are skipped."""
    folder = Path(folder)
    found = set()
    for root, dirs, files in os.walk(folder):
        dirs[:] = [d for d in dirs if not d.startswith(tuple(leave_out))]
        for name in dirs + files:
            found.add(str((Path(root) / name).relative_to(folder)))
    return found


@dataclass
class Interrupted:
    """What one interrupted run did."""

    args: list
    after_s: float
    status: int
    stdout: str
    stderr: str
    new_entries: list     # files or folders left behind that were not there before
    unwhole: list = ()    # why the outputs the line says were written in full are not

    def problems(self):
        """Why this run broke the contract ([] when it kept it; None when it ended before the
        interrupt, so it says nothing)."""
        if self.status == 0:
            return None
        found = []
        if self.status != 130:
            found.append(f"exit status {self.status}, not 130")
        if _LINE.fullmatch((self.stderr.strip().splitlines() or [""])[-1]) is None:
            found.append(f"stderr does not end with 'sma-fmu: interrupted': {self.stderr[-600:]!r}")
        other = [line for line in self.stderr.strip().splitlines()[:-1]
                 if not line.startswith("sma-fmu: ") or line.startswith("sma-fmu: error")]
        if other:
            found.append(f"stderr has other lines: {other[:5]}")
        if "Traceback" in self.stderr + self.stdout or "KeyboardInterrupt" in self.stderr + self.stdout:
            found.append("a traceback or KeyboardInterrupt was printed")
        written = _written(self.stderr)
        left = [entry for entry in self.new_entries
                if not any(entry == out or entry.startswith(f"{out}/") for out in written)]
        if left:
            found.append(f"left behind: {left[:8]}")
        return found + list(self.unwhole)


def _written(stderr):
    """The outputs the last line of ``stderr`` says were written in full (a list)."""
    last = _LINE.fullmatch((stderr.strip().splitlines() or [""])[-1])
    return last.group(1).split(", ") if last and last.group(1) else []


def _incomplete(out):
    """Why the output ``out`` is not whole ([] for a file, written by a rename, and for a
    folder holding exactly the entries its marker lists)."""
    if not out.is_dir():
        return [] if out.is_file() else ["not there"]
    try:
        listed = set(json.loads((out / MARKER).read_text(encoding="utf-8"))["entries"])
    except (OSError, ValueError, KeyError) as error:
        return [f"no readable {MARKER} ({error})"]
    held = {entry.name for entry in out.iterdir()} - {MARKER}
    return [f"{problem}: {sorted(names)[:5]}" for problem, names in
            (("missing", listed - held), ("not listed", held - listed)) if names]


def interrupt(args, work, after_s, timeout_s=120.0, environment=None, group=True, once=None):
    """Run ``sma-fmu args`` in the folder ``work`` and Ctrl-C it after ``after_s`` seconds;
    returns :class:`Interrupted`. ``work`` holds the inputs; its ``tmp/`` is made the
    process's temporary folder. ``group``: SIGINT to the whole process group (a terminal's
    Ctrl-C), else to sma-fmu alone (``kill -INT``, ``timeout -s INT``). ``once``: a glob
    pattern under ``work``; the ``after_s`` seconds count from when a file matches it."""
    work = Path(work)
    temporary = work / "tmp"
    temporary.mkdir(exist_ok=True)
    before = tree(work, _CACHE_PREFIXES)
    env = dict(os.environ if environment is None else environment)
    env.update(TMPDIR=str(temporary), PYTHONDONTWRITEBYTECODE="1")
    env.pop("PYTHONWARNINGS", None)
    process = subprocess.Popen(sma_fmu_command() + list(args), cwd=work, env=env,
                               stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        while once and process.poll() is None and not any(work.glob(once)):
            time.sleep(0.001)
        time.sleep(after_s)
        if process.poll() is None:
            (os.killpg if group else os.kill)(process.pid, signal.SIGINT)
        stdout, stderr = process.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        stdout, stderr = process.communicate()
        stderr += f"\n(no end {timeout_s} s after the interrupt: killed)"
    left = sorted(tree(work, _CACHE_PREFIXES) - before)
    unwhole = [f"{out}: said written in full, {problem}"
               for out in _written(stderr) for problem in _incomplete(work / out)]
    for name in left:   # the next run starts from the same inputs
        path = work / name
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path, ignore_errors=True)
        elif path.exists() or path.is_symlink():
            path.unlink()
    return Interrupted(list(args), after_s, process.returncode, stdout, stderr, left, unwhole)


def interrupt_in_time(args, work, after_s, earliest_s=0.3, **options):
    """:func:`interrupt`, again at half the moment (not before ``earliest_s`` [s]) while the
    command ended before its interrupt (a quick machine): returns the last
    :class:`Interrupted`, whose ``after_s`` is the moment used."""
    result = interrupt(args, work, after_s, **options)
    while result.status == 0 and after_s > earliest_s:
        after_s = max(earliest_s, round(after_s / 2, 2))
        result = interrupt(args, work, after_s, **options)
    return result
