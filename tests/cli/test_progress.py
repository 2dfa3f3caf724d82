"""Progress bars: each long command shows one on a terminal (a pseudo-terminal here, the pty
module), none when its output is piped, none with ``--quiet``."""
import fcntl
import os
import pty
import struct
import sys
import termios
import threading

import pytest

from sma_fmu.cli import main
from sma_fmu.console import progress

BAR = "%|"   # tqdm's bar: "label:  40%|████      | 2/5 [...]"


class Terminal:
    """A pseudo-terminal of 100 columns as sys.stderr; :meth:`text` is what was drawn on it."""

    def __init__(self):
        self.master, slave = pty.openpty()
        fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))
        self.stream = os.fdopen(slave, "w", buffering=1, encoding="utf-8")
        self.chunks = []
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        while True:
            try:
                data = os.read(self.master, 65536)
            except OSError:
                return
            if not data:
                return
            self.chunks.append(data)

    def text(self):
        self.stream.close()
        self.reader.join(timeout=10)
        os.close(self.master)
        return b"".join(self.chunks).decode("utf-8", "replace")


class _OnTerminal:
    """sys.stderr on a pseudo-terminal while a test's body runs (set in the body: pytest's
    capture sets sys.stderr again between a fixture and the test)."""

    def __init__(self):
        self.shown = None

    def __call__(self, work, *arguments):
        self.shown = Terminal()
        kept, sys.stderr = sys.stderr, self.shown.stream
        try:
            result = work(*arguments)
        finally:
            sys.stderr = kept
        return result, self.shown.text()


@pytest.fixture
def terminal(monkeypatch):
    """``terminal(function, *arguments)``: (its result, what it drew on a pseudo-terminal
    as stderr). Bars show at once (no delay): a step quicker than the delay on a fast
    machine still shows its bar."""
    monkeypatch.setattr(progress, "DELAY_S", 0.0)
    return _OnTerminal()


def _on_terminal(terminal, argv):
    return terminal(main, argv)


@pytest.mark.needs("gcc")
def test_run_shows_each_scenario_s_progress(terminal, fmus, tmp_path):
    status, text = _on_terminal(terminal, ["run", "heavy-pi", "--fmus", str(fmus["SmaActuator"].parent),
                                           "--out", str(tmp_path / "r")])
    assert status == 0 and BAR in text and "heavy-pi:" in text and "step" in text


@pytest.mark.needs("gcc")
def test_run_quiet_or_piped_shows_none(terminal, capsys, fmus, tmp_path):
    assert main(["run", "heavy-pi", "--fmus", str(fmus["SmaActuator"].parent),
                 "--out", str(tmp_path / "piped")]) == 0
    assert BAR not in capsys.readouterr().err
    status, text = _on_terminal(terminal, ["run", "heavy-pi", "--fmus", str(fmus["SmaActuator"].parent),
                                           "--quiet", "--out", str(tmp_path / "quiet")])
    assert status == 0 and BAR not in text


@pytest.mark.needs("gcc")
def test_build_shows_each_fmu(terminal, tmp_path):
    status, text = _on_terminal(terminal, ["build", "--out", str(tmp_path / "fmus")])
    assert status == 0 and "pythonfmu FMUs:" in text and BAR in text and "SmaActuator" in text


@pytest.mark.needs("gcc")
def test_a_native_build_shows_each_platform(terminal, tmp_path):
    from sma_fmu.fmi.packaging.build import build_fmus
    _, text = terminal(build_fmus, tmp_path / "native", None, ["SmaPwmDriver"], True)
    assert "native FMUs (FMI 2.0):" in text and "SmaPwmDriver linux64" in text and BAR in text


@pytest.mark.needs("gcc")
def test_check_shows_its_files_and_ends_with_a_count(terminal, fmus, capsys):
    files = [str(fmus["SmaPwmDriver"]), str(fmus["SmaScenarioSignals"])]
    status, text = _on_terminal(terminal, ["check", *files])
    assert status == 0 and "checking:" in text and BAR in text
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert last.startswith("check: 2 files, ") and " ok" in last and last.endswith("0 FAIL")


def test_tune_shows_its_generations(terminal, tmp_path):
    status, text = _on_terminal(terminal, ["tune", "heavy-pi", "--generations", "3", "--population", "2",
                                           "--stop-time", "3", "--out", str(tmp_path / "t")])
    assert status == 0 and "tuning heavy-pi:" in text and "generation" in text


def test_piped_output_gets_no_bar_at_all(capsys, tmp_path):
    assert main(["tune", "heavy-pi", "--generations", "2", "--population", "2", "--stop-time", "2",
                 "--out", str(tmp_path / "t")]) == 0
    captured = capsys.readouterr()
    assert BAR not in captured.err + captured.out and "\r" not in captured.err


def _demo():
    with progress.bar(2, "demo", unit="x", delay=0) as shown:
        progress.echo("a line of the command's own", file=sys.stderr)
        shown.update(2)


def test_a_line_printed_during_a_bar_keeps_it_whole(terminal):
    _, text = terminal(_demo)
    assert "a line of the command's own\r\n" in text and "demo:" in text
