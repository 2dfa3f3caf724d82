"""Driving sma_fmu/fmi/hosts/fmi_host.c: a plain C FMI host process, one command per line.

The host runs without libpython linked and without LD_PRELOAD, so what it shows is what
any C tool (fmusim, the FMI Library, libcosim) sees. A crash of the FMU is a crash of this
process, which the tests see as its exit status.
"""
import os
import subprocess
import zipfile
from dataclasses import dataclass, field
from pathlib import Path


OK, WARNING, DISCARD, ERROR, FATAL = range(5)


def unpack(fmu, folder):
    """Unzip ``fmu`` into ``folder`` (made if needed); returns the folder."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(fmu) as archive:
        archive.extractall(folder)
    for binary in (folder / "binaries").rglob("*.so"):
        binary.chmod(0o755)
    return folder


def text(value):
    """Hex argument for a string (None: a NULL pointer)."""
    if value is None:
        return "-"
    data = value if isinstance(value, bytes) else value.encode("utf-8")
    return data.hex() or "_"


def _unhex(word):
    return None if word == "-" else "" if word == "_" else bytes.fromhex(word).decode("utf-8", "replace")


@dataclass
class Reply:
    """What one command gave: its status, the values it printed, the log lines before it."""
    status: int
    values: list = field(default_factory=list)
    logs: list = field(default_factory=list)  # (status, category, text)

    def logged(self, at_least=WARNING):
        """Messages with a status of ``at_least`` or worse."""
        return [message for status, _, message in self.logs if status >= at_least]


class FmiHost:
    """A running fmi_host process for one unpacked FMU.

    Parameters
    ----------
    exe : Path
        The compiled host.
    folder : Path
        The unpacked FMU.
    env : dict, optional
        Environment (default: this process's, without LD_PRELOAD).
    runner : sequence of str, optional
        What runs the host (an emulator: ``qemu-aarch64 -L SYSROOT``).
    """

    def __init__(self, exe, folder, env=None, runner=()):
        if env is None:
            env = {k: v for k, v in os.environ.items() if k not in ("LD_PRELOAD", "SMA_FMU_LIBPYTHON")}
        self.process = subprocess.Popen([*runner, str(exe), str(folder)], stdin=subprocess.PIPE,
                                        stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                        text=True, env=env)

    def call(self, line):
        """Run one command; returns its :class:`Reply` (raises RuntimeError if the host died)."""
        self.process.stdin.write(line + "\n")
        self.process.stdin.flush()
        logs = []
        while True:
            answer = self.process.stdout.readline()
            if not answer:
                code = self.process.wait(timeout=30)
                raise RuntimeError(f"the host died (exit status {code}) at {line!r}: "
                                   f"{self.process.stderr.read()[-2000:]}")
            words = answer.split()
            if words[0] == "log":
                logs.append((int(words[1]), words[2], _unhex(words[3])))
            elif words[0] == "=":
                return Reply(int(words[1]), words[2:], logs)

    def close(self):
        """End the host (frees every instance); returns its exit status."""
        try:
            self.process.stdin.write("end\n")
            self.process.stdin.close()
        except (BrokenPipeError, ValueError):
            pass
        code = self.process.wait(timeout=60)
        self.process.stdout.close()
        self.process.stderr.close()
        return code

    @property
    def alive(self):
        return self.process.poll() is None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self.alive:
            self.close()
