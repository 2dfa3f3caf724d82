"""An editable install has no prebuilt binaries: without any compiler ``build --native
--fmi 3`` (which runs each FMU it builds) stops with one line naming the missing compiler
and the ways out, never an internal error, and leaves --out as it was."""
from fmpy import platform_tuple

from cli_failure import fails
from sma_fmu.fmi.packaging import prebuilt


def test_fmi3_without_a_compiler_names_it(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(prebuilt, "PREBUILT", tmp_path / "no-prebuilt-binaries")
    monkeypatch.setenv("CC", "no-such-cc")
    monkeypatch.setenv("SMA_FMU_WIN64_CC", "no-such-mingw-gcc")
    monkeypatch.setenv("SMA_FMU_ZIG_CC", "none")
    line = fails(capsys, ["build", "--native", "--fmi", "3", "--out", str(tmp_path / "fmi3")],
                 "build --native --fmi 3: no binary of SmaActuator for this machine "
                 f"({platform_tuple})", "pip install ziglang", "wheel")
    assert "internal error" not in line
    assert not (tmp_path / "fmi3").exists()
