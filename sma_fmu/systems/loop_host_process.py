"""The loop host as the C master's process: one ``loop_host.c`` (binary mode) for many runs.

The host reads a system and its run line from stdin, answers with frames on stdout (an
8-byte head: a 4-byte tag, the payload's length; see the source's header) and then waits
for the next system; it exits when stdin closes. :class:`HostProcess` sends it lines,
hands on its frames up to the end of a run and stops it. Its stderr goes to a temporary
file (:func:`host_stderr`), read when it died, so a long session never blocks on a full pipe. A
watchdog kills a host that sends nothing for ``timeout_s`` while the master waits for it
(only then: between runs the host waits for the master, not the other way round).
"""
import re
import subprocess
import tempfile
import threading
import time

__all__ = ["HostProcess", "STATUS_NAMES", "host_stderr", "log_entry", "failed_call"]

STATUS_NAMES = {2: "fmi2Discard", 3: "fmi2Error", 4: "fmi2Fatal"}
_FAIL = re.compile(r"(?P<name>[^.]+)\.(?P<call>.+) returned (?P<status>-?\d+) at t = (?P<time>\S+) s")


def _widen(pipe):
    """A 1 MiB pipe (Linux): the host steps on while the rows of two frames wait here."""
    try:
        import fcntl
        fcntl.fcntl(pipe.fileno(), getattr(fcntl, "F_SETPIPE_SZ", 1031), 1 << 20)
    except (ImportError, OSError):  # another system, or a lower pipe-max-size: the default
        pass


class _Watchdog:
    """Kills ``host`` when, while armed, :meth:`alive` was not called for ``seconds``
    (checked a few times a second from a thread of its own); ``fired`` says whether it did."""

    def __init__(self, host, seconds):
        self.host, self.seconds, self.fired = host, seconds, False
        self.last, self.armed = time.monotonic(), False
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._watch, name="c-master-watchdog", daemon=True)
        self._thread.start()

    def arm(self):
        self.last, self.armed = time.monotonic(), True

    def disarm(self):
        self.armed = False

    def alive(self):
        self.last = time.monotonic()

    def _watch(self):
        while not self._stop.wait(min(0.25, self.seconds / 4)):
            if self.armed and time.monotonic() - self.last > self.seconds:
                self.fired = True
                self.host.kill()
                return

    def stop(self):
        self._stop.set()
        self._thread.join()


def log_entry(payload):
    """(status, component, text) of a LOG_ frame."""
    head, _, text = payload.decode("utf-8", "replace").partition("\t")
    status, name, _category = (head.split(" ") + ["", ""])[:3]
    return int(status), name, text


def failed_call(text):
    """(component, call, status, time [s] or None) of a FAIL frame's ``text``, "NAME.CALL
    returned S at t = T s"; a text not of that form as it came, status fmi2Error."""
    match = _FAIL.fullmatch(text.strip())
    if match is None:
        return "?", text, 3, None
    return match["name"], match["call"], int(match["status"]), float(match["time"])


def host_stderr():
    """The file a host's stderr goes to (temporary: gone when closed)."""
    return tempfile.TemporaryFile()


class HostProcess:
    """One loop host ``process`` (a Popen with stdin and stdout pipes, its stderr the file
    ``stderr``), killed when it sends nothing for ``timeout_s`` [s] while :meth:`frames`
    waits for it."""

    def __init__(self, process, stderr, timeout_s):
        self.process, self._stderr = process, stderr
        _widen(self.process.stdout)
        self.watchdog = _Watchdog(self.process, timeout_s)
        self.closed = False

    @property
    def timed_out(self):
        """Whether the watchdog killed the host."""
        return self.watchdog.fired

    def send(self, lines):
        """Write ``lines`` (a list of text lines) to the host; False when it is gone."""
        try:
            self.process.stdin.write(("\n".join(lines) + "\n").encode())
            self.process.stdin.flush()
        except (BrokenPipeError, OSError):   # it exited (a bad system, fmi2Fatal) or was killed
            return False
        return True

    def frames(self, last=(b"DONE", b"FAIL")):
        """(tag, payload) frames from the host, up to and including one whose tag is in
        ``last``, or until the host closes its stdout (it died or was killed)."""
        stream, watchdog = self.process.stdout, self.watchdog
        watchdog.arm()
        try:
            while True:
                head = stream.read(8)
                if len(head) < 8:
                    return
                size = int.from_bytes(head[4:], "little")
                payload = stream.read(size) if size else b""
                if len(payload) < size:   # cut short: the host died (or was killed) in a frame
                    return
                watchdog.alive()
                yield head[:4], payload
                if head[:4] in last:
                    return
        finally:
            watchdog.disarm()

    def stderr_text(self):
        """What the host wrote to stderr so far."""
        self._stderr.seek(0)
        return self._stderr.read().decode("utf-8", "replace").strip()

    def close(self, kill=False):
        """End the host: close its stdin (it frees its instances and exits) and wait for
        it, killing it when ``kill`` or when it does not exit within a few seconds; its
        exit status."""
        if self.closed:
            return self.process.returncode
        self.closed = True
        if kill:
            self.process.kill()
        try:
            self.process.stdin.close()
        except OSError:
            pass
        try:
            status = self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            status = self.process.wait()
        self.watchdog.stop()
        self.process.stdout.close()
        return status

    def finish(self):
        """:meth:`close`, then the stderr text; the temporary file is gone after."""
        status = self.close()
        said = self.stderr_text()
        self._stderr.close()
        return status, said
