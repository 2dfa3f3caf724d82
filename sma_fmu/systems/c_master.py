"""The C master (``sma-fmu run --master c``): a scenario's closed loop stepped in C.

The loop host (``sma_fmu/fmi/hosts/loop_host.c``, mode "binary") loads the FMUs' binaries
through FMI and steps them Gauss-Seidel in :data:`~sma_fmu.fmi.loop.wiring.STEP_ORDER`, the order of
the fmpy master (:func:`~sma_fmu.cosim.master.run_fmus`): compensator, PI, driver, plant,
then the signals (SmaScenarioSignals, on the grid t_k = k h). It writes the recorded
outputs after initialization and after every step as raw doubles, in frames of
:data:`~sma_fmu.cosim.loop.ROWS_PER_CHUNK` samples, on a pipe; here they become the loop's
rows (:mod:`.c_master_rows`) and go to the sink in the fmpy master's blocks, so the
recorder, the metrics and the figures are those of the fmpy master, to the bit.

A missing FMU, a model whose variables do not match, or a failed call gets a named error
(:class:`CMasterError`): a failed step ends the run there, the rows up to it are given to
the sink (and kept in the error), and the message names the FMU, the call and the time.
A host that sends nothing for ``timeout_s`` seconds (a hung FMU) is killed and the run
fails naming the time it reached (:data:`DEFAULT_TIMEOUT_S`; ``sma-fmu run --timeout``).

With a :class:`~sma_fmu.cosim.recording.RunRecorder` writing CSV as the sink, the host
writes the CSV's rows itself (its "csv" line; the same text as the recorder's, byte for
byte, about ten times faster than Python's formatting); the recorder still gets every
row for the metrics and the figure.
"""
import os
import re
import subprocess
import threading
import time
from pathlib import Path

from sma_fmu.cosim.loop import ROWS_PER_CHUNK, LoopResult
from sma_fmu.fmi.driving.instance import FmuError
from sma_fmu.fmi.driving.unpacked import acquire, release
from sma_fmu.fmi.hosts import CHostError, compile_host
from sma_fmu.fmi.loop.system import check_variables
from sma_fmu.systems.c_master_rows import RowAssembler, csv_columns, recorded_columns
from sma_fmu.systems.closed_loop import closed_loop
from sma_fmu.systems.loop_host import loop_host_lines, wine_executable, wine_path

__all__ = ["MASTERS", "DEFAULT_TIMEOUT_S", "CMasterError", "run_c_master"]

MASTERS = ("fmpy", "c")   # `sma-fmu run --master`: the fmpy master, or this one
# [s] the longest the host may send nothing (choice: a frame of 4,096 steps takes about 1 ms,
# wine's start a few seconds; a minute of silence is a hung FMU, not a slow one)
DEFAULT_TIMEOUT_S = 60.0
_STATUS = {2: "fmi2Discard", 3: "fmi2Error", 4: "fmi2Fatal"}


class CMasterError(FmuError):
    """A run of the C master failed; ``rows`` holds the rows up to the failed step (a
    structured array, or None when the sink took them) and ``time_s`` the step's time [s]."""

    def __init__(self, message, status, rows=None, time_s=None):
        super().__init__(message, status)
        self.rows, self.time_s = rows, time_s


_HOSTS = {}   # the loop host's executable, by cache folder, platform and compiler settings


def _loop_host(cache, windows):
    """:func:`~sma_fmu.fmi.hosts.compile_host`'s loop host, looked up once per process (it
    hashes the sources and looks for the compiler on every call)."""
    key = (str(cache), windows, os.environ.get("CC"), os.environ.get("SMA_FMU_WIN64_CC"),
           os.environ.get("PATH"))
    executable = _HOSTS.get(key)
    if executable is None or not executable.is_file():
        executable = _HOSTS[key] = Path(compile_host("loop_host", cache, windows=windows))
    return executable


def _widen(pipe):
    """A 1 MiB pipe (Linux): the host steps on while the rows of two frames wait here."""
    try:
        import fcntl
        fcntl.fcntl(pipe.fileno(), getattr(fcntl, "F_SETPIPE_SZ", 1031), 1 << 20)
    except (ImportError, OSError):  # another system, or a lower pipe-max-size: the default
        pass


def _read_frames(stream):
    """(tag, payload) frames from the host's stdout until it closes."""
    while True:
        head = stream.read(8)
        if len(head) < 8:
            return
        size = int.from_bytes(head[4:], "little")
        payload = stream.read(size) if size else b""
        if len(payload) < size:   # cut short: the host died (or was killed) in a frame
            return
        yield head[:4], payload


class _Watchdog:
    """Kills ``host`` when :meth:`alive` was not called for ``seconds`` (checked a few times
    a second from a thread of its own); ``fired`` says whether it did."""

    def __init__(self, host, seconds):
        self.host, self.seconds, self.fired = host, seconds, False
        self.last = time.monotonic()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._watch, name="c-master-watchdog", daemon=True)
        self._thread.start()

    def alive(self):
        self.last = time.monotonic()

    def _watch(self):
        while not self._stop.wait(min(0.25, self.seconds / 4)):
            if time.monotonic() - self.last > self.seconds:
                self.fired = True
                self.host.kill()
                return

    def stop(self):
        self._stop.set()
        self._thread.join()


def _log_entry(payload):
    """(status, component, text) of a LOG_ frame."""
    head, _, text = payload.decode("utf-8", "replace").partition("\t")
    status, name, _category = (head.split(" ") + ["", ""])[:3]
    return int(status), name, text


_FAIL = re.compile(r"(?P<name>[^.]+)\.(?P<call>.+) returned (?P<status>-?\d+) at t = (?P<time>\S+) s")


def _failure(scenario, text, logs, rows, windows):
    """The :class:`CMasterError` of a FAIL frame ``text``: "NAME.CALL returned S at t = T s"."""
    match = _FAIL.fullmatch(text.strip())
    if match is None:  # not the host's form: say it as it came
        name, call, status, time_s = "?", text, 3, None
    else:
        name, call = match["name"], match["call"]
        status, time_s = int(match["status"]), float(match["time"])
    said = "; ".join(t for s, n, t in logs if n == name and s >= 2) or "no message"
    where = " (win64, wine)" if windows is not None else ""
    when = "" if time_s is None else f" at t = {time_s:g} s"
    message = (f"scenario {scenario.name}: C master{where}: {name}: {call} failed "
               f"({_STATUS.get(status, status)}){when}: {said}; the run stopped there "
               f"({rows} rows kept)")
    return CMasterError(message, status, time_s=time_s)


def run_c_master(scenario, fmu_dir, sink=None, windows=None, cache=None,
                 timeout_s=DEFAULT_TIMEOUT_S):
    """Run ``scenario`` through the FMUs in ``fmu_dir`` in the C master; a :class:`LoopResult`
    (``path`` "fmu"), its ``data`` None when ``sink`` took the rows (see
    :func:`~sma_fmu.cosim.loop.run_loop`). ``windows``: None for the linux64 build, else the
    environment of a wine64 prefix (the win64 host with the FMUs' win64 binaries).
    ``timeout_s``: the longest [s] the host may send nothing before it is killed.

    Raises :class:`~sma_fmu.fmi.loop.system.MissingFmuError` for a missing FMU, ``ValueError``
    naming an FMI 3.0 FMU (the host is an FMI 2.0 host) or the FMU and the variable when its
    variables do not match, and
    :class:`CMasterError` when a call fails (the rows up to that step kept) or the host
    sends nothing for ``timeout_s`` s (killed; the rows so far are not kept).
    """
    if not (isinstance(timeout_s, (int, float)) and timeout_s > 0):
        raise ValueError(f"the C master's timeout must be a number of seconds > 0, got {timeout_s!r}")
    started = time.perf_counter()
    system = closed_loop(scenario, fmu_dir)
    newer = sorted((c.model, str(c.fmu)) for c in system.components if c.fmi_version != "2")
    if newer:  # the loop host is an FMI 2.0 host (fmi2 calls, fmi2 binaries)
        raise ValueError(f"{newer[0][1]} is an FMI 3.0 FMU: the C master runs FMI 2.0 FMUs "
                         f"(sma-fmu build --native); run FMI 3.0 FMUs with --master fmpy")
    check_variables(system)
    unpacked = []   # each FMU unpacked once per process, removed at its exit (driving.unpacked)
    try:
        for component in system.components:
            unpacked.append(acquire(component.fmu))
        return _run(scenario, system, [u.folder for u in unpacked], sink, windows, cache,
                    timeout_s, started)
    finally:
        for folder in unpacked:
            release(folder)


def _run(scenario, system, unpacked, sink, windows, cache, timeout_s, started):
    """:func:`run_c_master` with the FMUs of ``system`` unpacked in the folders ``unpacked``."""
    folders = {c.name: folder for c, folder in zip(system.components, unpacked)}
    if windows is not None:
        folders = {name: wine_path(folder) for name, folder in folders.items()}
    try:
        executable = _loop_host(cache, windows is not None)
    except CHostError as error:   # no compiler: one named error, not an internal one
        raise CMasterError(f"scenario {scenario.name}: C master: {error}", 3) from None
    columns = recorded_columns(system)
    lines = loop_host_lines(system, {k: str(v) for k, v in folders.items()}, scenario.steps,
                            columns=columns)
    lines[-1] += f" binary {ROWS_PER_CHUNK}"
    text = getattr(sink, "csv_for_host", None)   # a RunRecorder writing CSV: the host writes it
    text = text() if text is not None else None
    if text is not None:
        path, every, last = text
        name = os.fsencode(path) if windows is None else wine_path(path).encode("utf-8")
        lines.insert(-1, f"csv {name.hex()} {every} {last} {csv_columns(columns)}")
    command = [str(executable)] if windows is None else [wine_executable(), str(executable)]
    environment = dict(os.environ if windows is None else windows)
    environment.pop("LD_PRELOAD", None)
    rows = RowAssembler(scenario, columns, sink)
    logs, failure, done = [], None, False
    with subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, env=environment) as host:
        watchdog = _Watchdog(host, timeout_s)
        try:
            _widen(host.stdout)
            try:
                host.stdin.write(("\n".join(lines) + "\n").encode())
                host.stdin.close()
            except BrokenPipeError:  # the host refused the system early: its stderr says why
                pass
            for tag, payload in _read_frames(host.stdout):
                watchdog.alive()
                if tag == b"ROWS":
                    rows.add(payload)
                elif tag == b"LOG_":
                    entry = _log_entry(payload)
                    if entry[0] >= 2:  # what a failure quotes (warnings are not kept: a long
                        logs.append(entry)  # run may log one per step)
                elif tag == b"FAIL":
                    failure = payload.decode("utf-8", "replace")
                elif tag == b"DONE":
                    done = True
        finally:
            watchdog.stop()
        said = host.stderr.read().decode("utf-8", "replace").strip()
        status = host.wait()
    where = " (win64, wine)" if windows is not None else ""
    if watchdog.fired:
        reached = rows.count * scenario.step_s if rows.started else 0.0
        raise CMasterError(f"scenario {scenario.name}: C master{where}: no output for "
                           f"{timeout_s:g} s at t = {reached:g} s: the host was stopped (an FMU "
                           f"hangs?); {rows.count} rows were recorded", 3, time_s=reached)
    if failure is not None:
        kept = rows.finish()   # the rows up to the failed step, the last without step outputs
        error = _failure(scenario, failure, logs, rows.count, windows)
        error.rows = kept
        raise error
    if status != 0 or not done:
        raise CMasterError(f"scenario {scenario.name}: C master{where}: exit status {status}: "
                           f"{said.splitlines()[-1] if said else 'no message'}", 3)
    data = rows.finish()
    return LoopResult(scenario, data, "fmu", time.perf_counter() - started)
