"""Ctrl-C for the command line: one line, exit status 130, no traceback, nothing half-written.

Python raises KeyboardInterrupt wherever the main thread is when SIGINT arrives. Two places
must not get it:

- Python code running *inside* an FMU call: a pythonfmu slave (in-process, its modules named
  ``<script>_<stamp>``, ``<script>_rt_<stamp>``..., see
  :mod:`sma_fmu.fmi.packaging.pythonfmu_build`), pythonfmu itself, or importlib while
  pythonfmu imports a slave. pythonfmu turns the exception into fmi2Fatal and frees the
  instance, the C front prints it with its traceback; a ctypes callback prints it and goes
  on. The handler installed by :func:`handle_interrupts` leaves such code alone and tries
  again 10 ms later, until the main thread is back in the master's own code.
- A section that must finish once started, :func:`deferred`: moving a command's results into
  place, removing its temporary folder (:mod:`sma_fmu.files.output_folder`). The
  KeyboardInterrupt comes at its end.

After the first KeyboardInterrupt, further Ctrl-C are ignored: the command is already on its
way out, cleaning up. :func:`seen` tells whether a Ctrl-C came at all: the command line then
reports "interrupted" whatever error the interrupt caused on its way (a compiler killed by the
same Ctrl-C, an FMU that saw it). Without :func:`handle_interrupts` (the package used as a
library) nothing here changes Python's behaviour.
"""
import contextlib
import itertools
import re
import signal
import sys
import threading

__all__ = ["handle_interrupts", "deferred", "seen", "in_fmu_code", "RETRY_S"]

RETRY_S = 0.01     # how soon a Ctrl-C that landed inside an FMU is delivered again [s]
# modules of a pythonfmu FMU's own code, as pythonfmu_build names them: <script>_<stamp> and
# <script>_<suffix>_<stamp>.<module>, the stamp 10 hex digits
_FMU_MODULE = re.compile(r"^[A-Za-z_]\w*_[0-9a-f]{10}(\.|$)")
_BUILD_TIME = ("pythonfmu.builder", "pythonfmu.csvbuilder", "pythonfmu.deploy")


class _State:
    installed = False
    seen = False        # a SIGINT arrived
    raised = False      # the KeyboardInterrupt has been raised: the command is ending
    pending = False     # one arrived inside a deferred section
    depth = 0           # deferred sections the main thread is in
    previous = None     # the handlers replaced (SIGINT, sys.unraisablehook)


def _module(frame):
    return frame.f_globals.get("__name__") or ""


def in_fmu_code(frame):
    """True if ``frame`` (the innermost one) is Python code an FMU call runs: a frame of a
    pythonfmu FMU's modules, of the functions they compile (no module name: the front's
    fast path calls them) or of pythonfmu (not its builder) on the stack, or importlib
    called from fmpy (pythonfmu importing a slave in fmi2Instantiate)."""
    names = []
    while frame is not None:
        names.append(_module(frame))
        frame = frame.f_back
    if any(not name   # code the slave support compiled (slave_support/compiled.py: no module)
           or _FMU_MODULE.match(name) or (name.startswith("pythonfmu") and not name.startswith(_BUILD_TIME))
           for name in names):
        return True
    outside = list(itertools.dropwhile(lambda name: name.startswith("importlib"), names))
    return len(outside) < len(names) and bool(outside) and outside[0].startswith("fmpy")


def _deliver_again():
    """SIGINT to the main thread once more, soon (a real signal: it ends a blocking call)."""
    main = threading.main_thread().ident

    def send():
        if not _State.installed or _State.raised:
            return
        if hasattr(signal, "pthread_kill"):
            signal.pthread_kill(main, signal.SIGINT)
        else:  # Windows
            import _thread
            _thread.interrupt_main()
    timer = threading.Timer(RETRY_S, send)
    timer.daemon = True
    timer.start()


def _handler(signum, frame):
    _State.seen = True
    if _State.raised:
        return                       # already ending: cleaning up is not interrupted
    if _State.depth:
        _State.pending = True        # delivered at the end of the section
        return
    if frame is not None and in_fmu_code(frame):
        _deliver_again()
        return
    _State.raised = True
    raise KeyboardInterrupt


def _unraisable(unraisable):
    """A KeyboardInterrupt that could not be raised (a ctypes callback's, a finalizer's) is
    not printed: it is delivered again."""
    if isinstance(unraisable.exc_value, KeyboardInterrupt) and _State.installed:
        _State.raised = False
        _deliver_again()
        return
    _State.previous[1](unraisable)


@contextlib.contextmanager
def handle_interrupts():
    """Install the SIGINT handler for the body (main thread only; elsewhere a no-op)."""
    if threading.current_thread() is not threading.main_thread() or _State.installed:
        yield
        return
    _State.seen = _State.raised = _State.pending = False
    _State.depth = 0
    _State.previous = (signal.signal(signal.SIGINT, _handler), sys.unraisablehook)
    sys.unraisablehook = _unraisable
    _State.installed = True
    try:
        yield
    finally:
        _State.installed = False
        signal.signal(signal.SIGINT, _State.previous[0])
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


def seen():
    """True if a Ctrl-C (SIGINT) arrived while :func:`handle_interrupts` was installed."""
    return _State.seen
