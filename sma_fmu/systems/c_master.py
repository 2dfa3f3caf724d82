"""The C master (``sma-fmu run --master c``): a scenario's closed loop stepped in C.

The loop host (``sma_fmu/fmi/hosts/loop_host.c``, mode "binary") loads the FMUs' binaries
through FMI and steps them Gauss-Seidel in :data:`~sma_fmu.fmi.loop.wiring.STEP_ORDER`, the order of
the fmpy master (:func:`~sma_fmu.cosim.master.run_fmus`): compensator, PI, driver, plant,
then the signals (SmaScenarioSignals, on the grid t_k = k h). It writes the recorded
outputs after initialization and after every step as raw doubles, in frames of
:data:`~sma_fmu.cosim.loop.ROWS_PER_CHUNK` samples, on a pipe; here they become the loop's
rows (:mod:`.c_master_rows`) and go to the sink in the fmpy master's blocks, so the
recorder, the metrics and the figures are those of the fmpy master, to the bit.

:class:`CMaster` pays the fixed cost once for many runs (the scenarios of one command, the
points of one study): one host process (:mod:`.loop_host_process`), each FMU file unpacked
once per process (:mod:`~sma_fmu.fmi.driving.unpacked`) and loaded once in the host, each
instance reset (fmi2Reset) between runs instead of freed. A run after a reset equals a
run in a fresh host, to the bit. :func:`run_c_master` is one run in a master of its own.

A missing FMU, a model whose variables do not match, or a failed call gets a named error
(:class:`CMasterError`): a failed step ends the run there, the rows up to it are given to
the sink (and kept in the error), and the message names the FMU, the call and the time.
**Choice: after a failed call (fmi2Discard, fmi2Error) the host stays** (no restart to
pay); that run's instances are freed and the next run makes new ones, so nothing of the
failed run reaches it. After fmi2Fatal, a host that died, or a timeout the next run starts
a new host. A host that sends nothing for ``timeout_s`` seconds while a run waits for it (a
hung FMU) is killed and the run fails naming the time it reached
(:data:`DEFAULT_TIMEOUT_S`; ``sma-fmu run --timeout``).

A stroke reference reaches the signals FMU as the R_ref table it maps to at every step; the
C master maps it in C (:mod:`sma_fmu.cosim.stroke_table`, the same text as the Python map's),
part of the run's wall time, not in Python (some 2.7 s before a 30-s run of the 0.5 Hz
profile).

With a :class:`~sma_fmu.cosim.recording.RunRecorder` writing CSV as the sink, the host
writes the CSV's rows itself (its "csv" line; the same text as the recorder's, byte for
byte, about ten times faster than Python's formatting); the recorder still gets every
row for the metrics and the figure.
"""
import os
import struct
import subprocess
import time
from pathlib import Path

from sma_fmu.cosim.loop import ROWS_PER_CHUNK, LoopResult
from sma_fmu.cosim.run_warnings import WarningTexts, model_text, ordered
from sma_fmu.cosim.stroke_table import available_program, stroke_table_text
from sma_fmu.fmi.driving.instance import FmuError
from sma_fmu.fmi.driving.unpacked import WIN64, acquire, release
from sma_fmu.fmi.hosts import CHostError, compile_host
from sma_fmu.fmi.loop.system import check_variables
from sma_fmu.runtime.signals import is_stroke
from sma_fmu.systems.loop_host_process import (STATUS_NAMES, HostProcess, failed_call,
                                               host_stderr, log_entry)
from sma_fmu.systems.c_master_rows import RowAssembler, csv_columns, recorded_columns
from sma_fmu.systems.closed_loop import closed_loop
from sma_fmu.systems.loop_host import loop_host_lines, wine_executable, wine_path

__all__ = ["MASTERS", "DEFAULT_TIMEOUT_S", "CMasterError", "CMaster", "run_c_master"]

MASTERS = ("fmpy", "c")   # `sma-fmu run --master`: the fmpy master, or this one
# [s] the longest the host may send nothing (choice: a frame of 4,096 steps takes about 1 ms,
# wine's start a few seconds; a minute of silence is a hung FMU, not a slow one)
DEFAULT_TIMEOUT_S = 60.0


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


def _failure(scenario, text, logs, rows, where):
    """The :class:`CMasterError` of a FAIL frame ``text``: "NAME.CALL returned S at t = T s"."""
    name, call, status, time_s = failed_call(text)
    said = "; ".join(t for s, n, t in logs if n == name and s >= 2) or "no message"
    when = "" if time_s is None else f" at t = {time_s:g} s"
    message = (f"scenario {scenario.name}: C master{where}: {name}: {call} failed "
               f"({STATUS_NAMES.get(status, status)}){when}: {said}; the run stopped there "
               f"({rows} rows kept)")
    return CMasterError(message, status, time_s=time_s)


class CMaster:
    """The C master over the FMUs in ``fmu_dir`` for many runs (:meth:`run`): one host
    process and the FMUs it loaded, kept until :meth:`close` (or the end of a ``with``).

    ``windows``: None for the linux64 build, else the environment of a wine64 prefix (the
    win64 host with the FMUs' win64 binaries). ``cache``: the host's build folder (default:
    the temporary folder). ``timeout_s``: the longest [s] the host may send nothing while a
    run waits for it before it is killed. ``startup_s`` [s]: the time spent so far starting
    hosts, reading the FMUs' model descriptions, unpacking the FMUs and loading them in the
    host (not part of any run's wall time);
    ``hosts_started``: how many host processes it started.
    """

    def __init__(self, fmu_dir, windows=None, cache=None, timeout_s=DEFAULT_TIMEOUT_S):
        if not (isinstance(timeout_s, (int, float)) and timeout_s > 0):
            raise ValueError(f"the C master's timeout must be a number of seconds > 0, got {timeout_s!r}")
        self.fmu_dir, self.windows, self.cache, self.timeout_s = fmu_dir, windows, cache, timeout_s
        self.where = " (win64, wine)" if windows is not None else ""
        self.startup_s, self.hosts_started = 0.0, 0
        self._host, self._loaded, self._described = None, set(), set()
        self._unpacked = {}   # FMU file -> Unpacked, held until close

    def __enter__(self):
        return self

    def __exit__(self, *_):
        self.close()

    def close(self):
        """Stop the host (it frees its instances) and end the use of the unpacked FMUs."""
        self._stop_host()
        for unpacked in self._unpacked.values():
            release(unpacked)
        self._unpacked = {}

    def host_cpu_s(self):
        """CPU time [s] the running host process has used (Linux; 0.0 without a host or
        elsewhere): the C side of the runs, for benchmarks."""
        try:
            with open(f"/proc/{self._host.process.pid}/stat", encoding="ascii") as stat:
                fields = stat.read().rpartition(")")[2].split()
        except (AttributeError, OSError):
            return 0.0
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    def _stop_host(self, kill=False):
        host, self._host, self._loaded = self._host, None, set()
        if host is None:
            return None, ""
        if kill:
            host.close(kill=True)
        return host.finish()

    def _held(self, path):
        """The :class:`~sma_fmu.fmi.driving.unpacked.Unpacked` this master holds of the FMU
        file ``path`` if it is of the file's current version, else None."""
        held, stat = self._unpacked.get(str(path)), os.stat(path)
        return held if held is not None and held.key[1:] == (stat.st_size, stat.st_mtime_ns) else None

    def _text(self, held):
        return wine_path(held.folder) if self.windows is not None else str(held.folder)

    def _folder(self, path):
        """The folder (text, as the host sees it) of the FMU file ``path``, unpacked once per
        file version (a rebuilt file: unpacked again, in a new host)."""
        held = self._held(path)
        if held is None and str(path) in self._unpacked:   # an older version
            self._stop_host()
            release(self._unpacked.pop(str(path)))
        if held is None:
            platforms = WIN64 if self.windows is not None else None   # what the host loads
            held = self._unpacked[str(path)] = acquire(path, platforms)
        return self._text(held)

    def _ready(self, system):
        """Whether a run of ``system`` needs no start-up: the host runs, its FMUs loaded."""
        if self._host is None or self._host.process.poll() is not None:
            return False
        helds = [self._held(c.fmu) for c in system.components]
        return all(held is not None and self._text(held) in self._loaded for held in helds)

    def _start(self, scenario, system):
        """Unpack the FMUs of ``system``, start a host if none runs and load those it has not
        loaded yet; {component: folder}. The time goes to :attr:`startup_s`."""
        started = time.perf_counter()
        try:
            folders = {c.name: self._folder(c.fmu) for c in system.components}
            if self._host is not None and self._host.process.poll() is not None:
                self._stop_host()   # it died between runs (killed from outside): a new one
            if self._host is None:
                try:
                    executable = _loop_host(self.cache, self.windows is not None)
                except CHostError as error:   # no compiler: one named error, not an internal one
                    raise CMasterError(f"scenario {scenario.name}: C master: {error}", 3) from None
                command = ([str(executable)] if self.windows is None
                           else [wine_executable(), str(executable)])
                environment = dict(os.environ if self.windows is None else self.windows)
                environment.pop("LD_PRELOAD", None)
                stderr = host_stderr()
                process = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                           stderr=stderr, env=environment)
                self._host = HostProcess(process, stderr, self.timeout_s)
                self.hosts_started += 1
            new = [folder for folder in dict.fromkeys(folders.values()) if folder not in self._loaded]
            if new and not (self._host.send([f"load {folder}" for folder in new])
                            and all(self._loaded_one() for _ in new)):
                self._host_died(scenario, None, 0.0)
            self._loaded.update(new)
            return folders
        finally:
            self.startup_s += time.perf_counter() - started

    def _loaded_one(self):
        """Whether the host's next frame is the answer to a load line."""
        return [tag for tag, _ in self._host.frames(last=(b"LOAD",))][-1:] == [b"LOAD"]

    def _host_died(self, scenario, rows, reached):
        """Raise the :class:`CMasterError` of a host that died, or that the watchdog killed
        (``rows``: the rows recorded, or None before the run; ``reached`` [s]: its time)."""
        timed_out = self._host.timed_out
        status, said = self._stop_host(kill=True)
        if timed_out:
            raise CMasterError(f"scenario {scenario.name}: C master{self.where}: no output for "
                               f"{self.timeout_s:g} s at t = {reached:g} s: the host was stopped "
                               f"(an FMU hangs?); {rows or 0} rows were recorded", 3, time_s=reached)
        raise CMasterError(f"scenario {scenario.name}: C master{self.where}: exit status {status}: "
                           f"{said.splitlines()[-1] if said else 'no message'}", 3)

    def _lines(self, scenario, system, folders, columns, sink):
        """The host's lines for one run of ``system`` (the CSV line when ``sink`` hands its
        CSV file to the host)."""
        lines = loop_host_lines(system, folders, scenario.steps, columns=columns)
        lines[-1] += f" binary {ROWS_PER_CHUNK}"
        text = getattr(sink, "csv_for_host", None)   # a RunRecorder writing CSV: the host writes it
        text = text() if text is not None else None
        if text is not None:
            path, every, last = text
            name = os.fsencode(path) if self.windows is None else wine_path(path).encode("utf-8")
            lines.insert(-1, f"csv {name.hex()} {every} {last} {csv_columns(columns)}")
        return lines

    def _system(self, scenario):
        """The checked loop system of ``scenario`` (reading model descriptions the master had
        not read yet is start-up)."""
        started = time.perf_counter()
        text = None
        if is_stroke(scenario.reference):   # the stroke's R_ref table, mapped in C (part of the run)
            # compiled once: start-up; None without a compiler (a wheel's prebuilt host):
            # mapped in Python
            program = available_program(self.cache)
            self.startup_s += time.perf_counter() - started
            started = time.perf_counter()
            text = None if program is None else stroke_table_text(scenario, program)
        system = closed_loop(scenario, self.fmu_dir, reference_text=text)
        files = {str(c.fmu) for c in system.components}
        if not files <= self._described:
            self.startup_s += time.perf_counter() - started
            self._described |= files
        newer = sorted((c.model, str(c.fmu)) for c in system.components if c.fmi_version != "2")
        if newer:  # the loop host is an FMI 2.0 host (fmi2 calls, fmi2 binaries)
            raise ValueError(f"{newer[0][1]} is an FMI 3.0 FMU: the C master runs FMI 2.0 FMUs "
                             f"(sma-fmu build --native); run FMI 3.0 FMUs with --master fmpy")
        check_variables(system)
        return system

    def _send(self, run):
        """Give the host the lines of ``run`` (a :class:`_Run`), after the start-up it needs."""
        folders = self._start(run.scenario, run.system)
        read = run.columns
        columns = recorded_columns(run.system, read)
        missing = () if read is None else [c for c in run.system.outputs if c not in columns]
        run.rows = RowAssembler(run.scenario, columns, run.sink, missing)
        lines = self._lines(run.scenario, run.system, folders, columns,
                            run.sink if read is None else None)
        run.host, run.sent = self._host, self._host.send(lines)
        return run

    def _finish(self, run):
        """Read the frames of ``run``, sent before; its :class:`LoopResult`. A run sent to a
        host that a run before it ended (fmi2Fatal, a timeout) is sent again to a new one."""
        if run.host is not self._host:
            self._send(run)
        scenario, rows = run.scenario, run.rows
        logs, warnings, failure, done, writing = [], {}, None, False, 0.0
        try:
            if run.sent:
                for tag, payload in self._host.frames():
                    if tag == b"ROWS":
                        rows.add(payload)
                    elif tag == b"LOG_":
                        entry = log_entry(payload)
                        if entry[0] >= 2:  # what a failure quotes
                            logs.append(entry)
                        elif entry[0] == 1:  # a warning: each text once (a bounded number)
                            texts = warnings.get(entry[1]) or warnings.setdefault(entry[1], WarningTexts())
                            texts.add(model_text(entry[2]))
                    elif tag == b"FAIL":
                        failure = payload.decode("utf-8", "replace")
                    elif tag == b"DONE":   # with the seconds the host spent writing the CSV
                        done, writing = True, struct.unpack("<d", payload)[0]
        except BaseException:   # the sink failed, or an interrupt: the host is mid-run
            self._stop_host(kill=True)
            raise
        if failure is not None:
            kept = rows.finish()   # the rows up to the failed step, the last without step outputs
            error = _failure(scenario, failure, logs, rows.count, self.where)
            if error.status >= 4:   # fmi2Fatal: the host ended itself
                self._stop_host(kill=True)
            error.rows = kept
            raise error
        if not done:
            self._host_died(scenario, rows.count, rows.count * scenario.step_s if rows.started else 0.0)
        data = rows.finish()
        wall = time.perf_counter() - run.started - (self.startup_s - run.before) - writing
        return LoopResult(scenario, data, "fmu", wall, ordered(warnings))

    def run(self, scenario, sink=None, columns=None):
        """Run ``scenario``; a :class:`LoopResult` (``path`` "fmu"), its ``data`` None when
        ``sink`` took the rows (see :func:`~sma_fmu.cosim.loop.run_loop`), its
        ``wall_time_s`` the run's own: the start-up it needed is in :attr:`startup_s`, and
        the time the host spent writing a CSV (as the recorder's, not the run's) is left out.
        ``columns``: the loop's columns the sink reads (e.g.
        :attr:`~sma_fmu.cosim.metrics.StreamingMetrics.COLUMNS_READ`); the host records only
        those, the others are NaN (False) in the rows. None: every column.

        Raises :class:`~sma_fmu.fmi.loop.system.MissingFmuError` for a missing FMU,
        ``ValueError`` naming an FMI 3.0 FMU (the host is an FMI 2.0 host) or the FMU and
        the variable when its variables do not match, and :class:`CMasterError` when a call
        fails (the rows up to that step kept), the host died, or it sent nothing for
        ``timeout_s`` s (killed; the rows so far are not kept).
        """
        run = _Run(scenario, sink, columns, time.perf_counter(), self.startup_s)
        run.system = self._system(scenario)
        return self._finish(self._send(run))

    def run_many(self, items, columns=None):
        """Run the (scenario, sink) pairs of ``items`` one after another, each given to the
        host before the rows of the one before it are read, so the host goes on to the next
        run without waiting for the master (on a busy machine each wait is a wait for a
        core); yields, in order, each run's :class:`LoopResult` or the ``ValueError`` /
        :class:`CMasterError` it failed with (as :meth:`run` raises them). ``columns``: as
        for :meth:`run`. A run that needs a start-up (a new host, an FMU not loaded yet)
        waits for the one before it."""
        ahead = None   # a run given to the host, its rows not read yet
        for scenario, sink in items:
            run = _Run(scenario, sink, columns, time.perf_counter(), self.startup_s)
            try:
                run.system = self._system(scenario)
                if ahead is not None and not self._ready(run.system):
                    yield self._outcome(ahead)
                    ahead = None
                self._send(run)
            except (ValueError, RuntimeError) as error:
                if ahead is not None:
                    yield self._outcome(ahead)
                    ahead = None
                yield error
                continue
            if ahead is not None:
                yield self._outcome(ahead)
                run.started = max(run.started, time.perf_counter())   # its rows are read now
            ahead = run
        if ahead is not None:
            yield self._outcome(ahead)

    def _outcome(self, run):
        try:
            return self._finish(run)
        except (ValueError, RuntimeError) as error:
            return error


class _Run:
    """One run of a :class:`CMaster`: what it runs and where its rows go, and its state."""

    def __init__(self, scenario, sink, columns, started, before):
        self.scenario, self.sink, self.columns = scenario, sink, columns
        self.started, self.before = started, before   # [s]: perf_counter, startup_s then
        self.system = self.rows = self.host = None
        self.sent = False


def run_c_master(scenario, fmu_dir, sink=None, windows=None, cache=None,
                 timeout_s=DEFAULT_TIMEOUT_S):
    """Run ``scenario`` through the FMUs in ``fmu_dir`` in a C master of its own (a new host,
    stopped at the end; :meth:`CMaster.run` says what it returns and raises). Its
    ``wall_time_s`` includes that host's start and loading its FMUs."""
    started = time.perf_counter()
    with CMaster(fmu_dir, windows, cache, timeout_s) as master:
        result = master.run(scenario, sink)
    result.wall_time_s = time.perf_counter() - started
    return result

