"""A rerun into the same --out folder replaces what sma-fmu wrote there before, whole, keeps
what it did not write, and says which; a failed or interrupted commit leaves the folder."""
import json

import pytest

from sma_fmu.cli import main
from sma_fmu.console import interrupts
from sma_fmu.files.output_folder import MARKER, staged_folder


def _names(folder):
    return sorted(p.name for p in folder.iterdir())


def test_a_rerun_replaces_the_previous_results_whole_and_keeps_yours(tmp_path, capsys):
    out = tmp_path / "results"
    assert main(["run", "heavy-pi", "load-step-pi", "--path", "library", "--out", str(out)]) == 0
    assert _names(out) == sorted([MARKER, "comparison.md", "heavy-pi", "load-step-pi", "summary.json"])
    (out / "notes.txt").write_text("mine")
    capsys.readouterr()
    assert main(["run", "heavy-pi", "--path", "library", "--out", str(out)]) == 0
    assert _names(out) == sorted([MARKER, "comparison.md", "heavy-pi", "notes.txt", "summary.json"])
    err = capsys.readouterr().err.splitlines()
    assert f"sma-fmu: {out}: replaced the results written there before" in err
    assert f"sma-fmu: {out}: kept 1 entry sma-fmu did not write: notes.txt" in err
    assert json.loads((out / MARKER).read_text())["entries"] == ["comparison.md", "heavy-pi",
                                                                 "summary.json"]


def test_a_folder_sma_fmu_never_wrote_keeps_everything_else(tmp_path, capsys):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "data.csv").write_text("1,2")
    assert main(["run", "heavy-pi", "--path", "library", "--out", str(out)]) == 0
    assert "data.csv" in _names(out) and "heavy-pi" in _names(out)
    assert "kept 1 entry sma-fmu did not write: data.csv" in capsys.readouterr().err


def test_a_marker_never_reaches_outside_the_folder(tmp_path):
    out, outside = tmp_path / "out", tmp_path / "precious.txt"
    outside.write_text("keep")
    out.mkdir()
    (out / MARKER).write_text(json.dumps({"entries": ["../precious.txt", "..", "/etc", ""]}))
    with staged_folder(out) as stage:
        (stage / "new.txt").write_text("new")
    assert outside.read_text() == "keep" and _names(out) == [MARKER, "new.txt"]


def test_a_ctrl_c_in_a_deferred_section_still_leaves_no_output(tmp_path):
    out = tmp_path / "out"
    with interrupts.handle_interrupts():
        with pytest.raises(KeyboardInterrupt):
            with staged_folder(out) as stage:
                (stage / "a.txt").write_text("a")
                with interrupts.deferred():   # the same section the commit runs in
                    import signal
                    signal.raise_signal(signal.SIGINT)
                    (stage / "b.txt").write_text("b")
    assert not out.exists() and list(tmp_path.iterdir()) == []
