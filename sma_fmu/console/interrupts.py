"""Ctrl-C for the command line: one line, exit status 130, no traceback, nothing half-written.

Python raises KeyboardInterrupt wherever the main thread is when SIGINT arrives. Three places
must not get it:

- Python code running *inside* an FMU call: a pythonfmu slave (in-process, its modules named
  ``<script>_<stamp>``, ``<script>_rt_<stamp>``..., see
  :mod:`sma_fmu.fmi.packaging.pythonfmu_build`), pythonfmu itself, or importlib while
  pythonfmu imports a slave. pythonfmu turns the exception into fmi2Fatal and frees the
  instance, the C front prints it with its traceback; a ctypes callback prints it and goes
  on. The handler installed by :func:`handle_interrupts` leaves such code alone and raises
  the KeyboardInterrupt in the frame that called into the FMU, when the call returns (it
  traces that frame, as a debugger does).
- :mod:`tempfile` making or removing a temporary folder (pythonfmu's build folder, cut
  mid-removal, stayed behind): treated as FMU code, the KeyboardInterrupt comes when it returns.
- A section that must finish once started, :func:`deferred`: moving a command's results into
  place, removing its temporary folder (:mod:`sma_fmu.files.output_folder`). The
  KeyboardInterrupt comes at its end.

A child process (a compiler) started with :func:`run_child` ends with the command: on a
Ctrl-C it is asked to end (SIGTERM to its process group: its cc1 and as end too), then
killed; a compiler's temporary files go to a folder of its own, removed after it.

After the first KeyboardInterrupt, further Ctrl-C are ignored: the command is already on its
way out, cleaning up. A Ctrl-C that comes once a command's results are in place (during the
move that puts them there, or in what the command does after it: printing its summary) cannot
undo them: :func:`placed_output` records each, and the command line names them in its one line
(``sma-fmu: interrupted after writing results in full``); exit status 130 all the same, so a
script stops there. :func:`seen` tells whether a Ctrl-C came at all: the command line then
reports "interrupted" whatever error the interrupt caused on its way (a compiler killed by
the same Ctrl-C, an FMU that saw it). Without :func:`handle_interrupts` (the package used as a
library) nothing here changes Python's behaviour.
"""
import contextlib
import itertools
import os
import re
import signal
import subprocess
import sys
import tempfile
import threading

__all__ = ["handle_interrupts", "deferred", "children_spared", "seen", "placed_output",
           "outputs_placed", "in_fmu_code", "run_child", "CHILD_GRACE_S"]

CHILD_GRACE_S = 5.0   # how long a child (a compiler) may take to end when asked [s]
# modules of a pythonfmu FMU's own code, as pythonfmu_build names them: <script>_<stamp> and
# <script>_<suffix>_<stamp>.<module>, the stamp 10 hex digits
_FMU_MODULE = re.compile(r"^[A-Za-z_]\w*_[0-9a-f]{10}(\.|$)")
_BUILD_TIME = ("pythonfmu.builder", "pythonfmu.csvbuilder", "pythonfmu.deploy")
# modules a Ctrl-C does not cut either, as FMU code: tempfile, making or removing a temporary
# folder (a TemporaryDirectory's removal cut mid-way left pythonfmu's build folder behind)
_UNCUT = ("tempfile",)


class _State:
    installed = False
    traced = []         # the frames that raise KeyboardInterrupt at their next event
    seen = False        # a SIGINT arrived
    raised = False      # the KeyboardInterrupt has been raised: the command is ending
    pending = False     # one arrived inside a deferred section
    depth = 0           # deferred sections the main thread is in
    placed = []         # outputs moved into place, complete (paths as given)
    previous = None     # the handlers replaced (SIGINT, sys.unraisablehook)


def _module(frame):
    return frame.f_globals.get("__name__") or ""


def _fmu_code(name):
    """True for the module name of a frame an FMU runs (a nameless one: code the slave
    support compiled, slave_support/compiled.py, which the front's fast path calls)."""
    return not name or bool(_FMU_MODULE.match(name)) or (
        name.startswith("pythonfmu") and not name.startswith(_BUILD_TIME))


def _outside_fmu(frame, also=()):
    """``frame`` if it runs no FMU code, else the frame just outside the outermost frame of
    FMU code on the stack (the master's, which called into the FMU); importlib frames called
    from fmpy (pythonfmu importing a slave in fmi2Instantiate) count as FMU code, and so do
    the frames of the modules ``also``."""
    stack = []
    while frame is not None:
        stack.append(frame)
        frame = frame.f_back
    names = [_module(each) for each in stack]
    inside = [index for index, name in enumerate(names) if _fmu_code(name) or name in also]
    last = max(inside, default=-1)
    imports = sum(1 for _ in itertools.takewhile(lambda name: name.startswith("importlib"), names))
    if 0 < imports < len(names) and names[imports].startswith("fmpy"):
        last = max(last, imports - 1)
    return stack[min(last + 1, len(stack) - 1)] if stack else None


def in_fmu_code(frame):
    """True if ``frame`` (the innermost one) is Python code an FMU call runs."""
    return _outside_fmu(frame) is not frame


def _stop_tracing():
    sys.settrace(None)
    for frame in _State.traced:
        frame.f_trace = None
    _State.traced = []


def _raise_here(frame, event, arg):
    """The trace function of the frames outside the FMU: the first event (the FMU call has
    returned) raises the KeyboardInterrupt there."""
    _stop_tracing()
    if _State.raised or not _State.installed:
        return None
    _State.raised = True
    raise KeyboardInterrupt


def _interrupt_in(frame):
    """Raise KeyboardInterrupt in ``frame`` at its next line (or in a caller, if it returns
    first), as a debugger stops there: the frames from it outward are traced, no new one."""
    _State.traced = []
    while frame is not None:
        frame.f_trace = _raise_here
        _State.traced.append(frame)
        frame = frame.f_back
    sys.settrace(lambda frame, event, arg: None)


def _handler(signum, frame):
    _State.seen = True
    if _State.raised or _State.traced:
        return                       # already ending (cleaning up is not interrupted), or soon
    if _State.depth:
        _State.pending = True        # delivered at the end of the section
        return
    outside = None if frame is None else _outside_fmu(frame, _UNCUT)
    if outside is not None and outside is not frame:
        _interrupt_in(outside)       # when the FMU call returns
        return
    _State.raised = True
    raise KeyboardInterrupt


def _unraisable(unraisable):
    """A KeyboardInterrupt that could not be raised (in a ctypes callback) is not printed: it
    is raised in the frame that called into C, when the call returns."""
    if isinstance(unraisable.exc_value, KeyboardInterrupt) and _State.installed:
        _State.raised = False
        _interrupt_in(_outside_fmu(sys._getframe(1), _UNCUT))
        return
    _State.previous[1](unraisable)


@contextlib.contextmanager
def handle_interrupts(then_ignore=False):
    """Install the SIGINT handler for the body (main thread only; elsewhere a no-op).
    ``then_ignore``: after the body, ignore SIGINT instead of restoring the handler before
    it (a process about to exit: a Ctrl-C while the interpreter shuts down would otherwise
    kill it by the signal, or raise KeyboardInterrupt outside the command, its work done)."""
    if threading.current_thread() is not threading.main_thread() or _State.installed:
        yield
        return
    _State.seen = _State.raised = _State.pending = False
    _State.depth, _State.traced, _State.placed = 0, [], []
    _State.previous = (signal.signal(signal.SIGINT, _handler), sys.unraisablehook)
    sys.unraisablehook = _unraisable
    _State.installed = True
    try:
        yield
    finally:
        _State.installed = False
        _stop_tracing()
        signal.signal(signal.SIGINT, signal.SIG_IGN if then_ignore else _State.previous[0])
        sys.unraisablehook = _State.previous[1]


@contextlib.contextmanager
def deferred():
    """A section Ctrl-C does not cut: a SIGINT inside it raises KeyboardInterrupt at its end
    (with :func:`handle_interrupts` installed, in the main thread; otherwise a no-op)."""
    if not _State.installed or threading.current_thread() is not threading.main_thread():
        yield
        return
    _State.depth += 1
    try:
        yield
    finally:
        _State.depth -= 1
        if not _State.depth and _State.pending and not _State.raised:
            _State.pending = False
            _State.raised = True
            raise KeyboardInterrupt


@contextlib.contextmanager
def children_spared():
    """Start processes that a terminal's Ctrl-C must not reach (Dask's worker processes): the
    body runs with SIGINT blocked in this thread, and the threads and processes it starts
    inherit the block, so the Ctrl-C (sent to the whole process group) reaches this process
    alone, which shuts them down in order. A Ctrl-C meanwhile arrives when the body ends.
    Without ``signal.pthread_sigmask`` (Windows) or off the main thread: a no-op."""
    if not hasattr(signal, "pthread_sigmask") or \
            threading.current_thread() is not threading.main_thread():
        yield
        return
    # multiprocessing's resource tracker starts with SIGINT blocked, then *unblocks* it in the
    # starting thread (not restored): started here first, before the block, it is not
    # started again in the thread that spawns the workers (Dask's IO loop)
    import multiprocessing.resource_tracker
    multiprocessing.resource_tracker.ensure_running()
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def placed_output(path):
    """Record that ``path``, a command's output, has been moved into place whole (with
    :func:`handle_interrupts` installed; otherwise a no-op)."""
    if _State.installed:
        _State.placed.append(str(path))


def outputs_placed():
    """The outputs :func:`placed_output` recorded since :func:`handle_interrupts` began that
    are still there (a build's intermediate one, in a temporary folder, is gone)."""
    return [path for path in _State.placed if os.path.lexists(path)]


def seen():
    """True if a Ctrl-C (SIGINT) arrived while :func:`handle_interrupts` was installed."""
    return _State.seen


def _end_group(process):
    """Ask ``process`` and its children to end (SIGTERM to its group), kill them if they
    do not within :data:`CHILD_GRACE_S`."""
    def send(signum):
        with contextlib.suppress(OSError):
            if hasattr(os, "killpg"):
                os.killpg(process.pid, signum)
            else:  # Windows: the process alone
                process.kill() if signum != signal.SIGTERM else process.terminate()
    send(signal.SIGTERM)
    try:
        process.wait(timeout=CHILD_GRACE_S)
    except subprocess.TimeoutExpired:
        send(getattr(signal, "SIGKILL", signal.SIGTERM))
        process.wait()


def run_child(command, timeout=None, own_temp=False, **options):
    """:func:`subprocess.run` with ``capture_output=True``, in a process group of its own,
    which ends with the command: on a Ctrl-C (any exception here) or after ``timeout``
    seconds (then :class:`subprocess.TimeoutExpired`) the group is asked to end, then
    killed. Returns the :class:`subprocess.CompletedProcess`.

    ``own_temp``: the child (a compiler) gets a temporary folder of its own as TMPDIR (TMP,
    TEMP), removed when it has ended: a gcc ended by a Ctrl-C does not always remove its
    ``cc*.s`` and ``cc*.o`` (its ``as`` may still hold them), and nothing may be left behind."""
    if not own_temp:
        return _run_group(command, timeout, options)
    with tempfile.TemporaryDirectory(prefix="sma-fmu-child-", ignore_cleanup_errors=True) as temp:
        env = dict(options.pop("env", None) or os.environ)
        env.update(TMPDIR=temp, TMP=temp, TEMP=temp)
        return _run_group(command, timeout, dict(options, env=env))


def _run_group(command, timeout, options):
    with subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, start_new_session=hasattr(os, "killpg"),
                          **options) as process:
        try:
            stdout, stderr = process.communicate(timeout=timeout)
        except BaseException:
            _end_group(process)
            raise
    return subprocess.CompletedProcess(command, process.returncode, stdout, stderr)
