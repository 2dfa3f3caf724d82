"""sma-fmu export (SSP, container) and sma-fmu check, through the command line.

The check runs on every FMU, SSP and container this test session builds: the project's
own CI use of it (README's test command runs this file).
"""
import dataclasses
import zipfile

import pytest

from sma_fmu.cli import main
from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios
from sma_fmu.systems.closed_loop import closed_loop
from sma_fmu.systems.ssp import write_ssp
from sma_fmu.files.output_folder import MARKER
from system_needs import needs


@pytest.fixture(scope="module")
def exported(fmu_dir, tmp_path_factory):
    """Every paper scenario's SSP (a folder) and two containers, exported by the CLI."""
    folder = tmp_path_factory.mktemp("exported")
    assert main(["export", "ssp", "paper", "--out", str(folder / "ssp"), "--fmus", str(fmu_dir)]) == 0
    for name in ("heavy-pi", "load-step-pi+ff-adaptive"):
        assert main(["export", "container", name, "--out", str(folder / f"{name}.fmu"),
                     "--fmus", str(fmu_dir)]) == 0
    return folder


def test_export_writes_one_ssp_per_scenario_into_a_folder(exported):
    names = sorted(p.name for p in (exported / "ssp").iterdir())
    assert names == sorted([MARKER] + [f"{name}.ssp" for name in
                           ("load-step-pi", "load-step-pi+ff-fixed", "load-step-pi+ff-adaptive",
                            "heavy-pi", "heavy-pi+ff-fixed", "heavy-pi+ff-adaptive")])
    with zipfile.ZipFile(exported / "ssp" / "heavy-pi+ff-fixed.ssp") as archive:
        assert "resources/SmaFeedforward.fmu" in archive.namelist()


def test_export_of_one_scenario_to_a_file_writes_that_file_only(fmu_dir, tmp_path, capsys):
    out = tmp_path / "one.ssp"
    assert main(["export", "ssp", "heavy-pi", "--out", str(out), "--fmus", str(fmu_dir)]) == 0
    assert capsys.readouterr().out.splitlines() == [str(out)]
    assert list(tmp_path.iterdir()) == [out]
    with zipfile.ZipFile(out) as archive:
        assert "resources/SmaActuator.fmu" in archive.namelist()


@pytest.mark.parametrize("argv, message", [
    (["export", "ssp", "paper", "--out", "{tmp}/one.ssp"], "--out {tmp}/one.ssp: 6 scenarios need a folder"),
    (["export", "container", "paper", "--out", "{tmp}/c.fmu"], "names 6 scenarios; a container holds one"),
    (["export", "container", "heavy-pi", "--out", "{tmp}/c.zip"], "name it NAME.fmu"),
    (["export", "ssp", "no-such-scenario", "--out", "{tmp}/x.ssp"], "unknown scenario 'no-such-scenario'"),
    (["export", "ssp", "heavy-pi", "--out", "{tmp}/x.ssp", "--fmus", "{tmp}/none"],
     "{tmp}/none/SmaScenarioSignals.fmu not found; build the FMUs first"),
])
def test_export_errors_name_the_argument_and_write_nothing(fmu_dir, tmp_path, capsys, argv, message):
    argv = [a.format(tmp=tmp_path) for a in argv]
    if "--fmus" not in argv:
        argv += ["--fmus", str(fmu_dir)]
    assert main(argv) == 2
    error = capsys.readouterr().err
    assert error.startswith("sma-fmu: error: ") and message.format(tmp=tmp_path) in error
    assert list(tmp_path.iterdir()) == []


@needs("gcc", "mingw-w64")  # the C host (libcosim) and platform win64
def test_check_passes_on_everything_built(fmus, exported, capsys):
    files = list(fmus.values()) + sorted((exported / "ssp").glob("*.ssp"))[:2]
    files += sorted(exported.glob("*.fmu"))
    assert main(["check", *map(str, files)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert not [line for line in lines if line.startswith("FAIL")]
    for path in fmus.values():  # five checks and two platforms per FMU, each passed
        assert [line.split(": ")[1] for line in lines if line.startswith(f"ok    {path}:")] == [
            "fmpy validation", "FMI checker", "C host (libcosim)", "state round trip",
            "default experiment", "platform linux64", "platform win64"]
    container = exported / "heavy-pi.fmu"
    assert f"n/a   {container}: state round trip: the FMU does not declare canGetAndSetFMUstate" in lines
    assert any(line.startswith(f"n/a   {container}: default experiment: no ") for line in lines)
    assert any(line.startswith("ok") and "SSD schema" in line for line in lines)


@needs("gcc")  # the C host (libcosim) must run to fail on it
def test_check_fails_on_a_system_that_cannot_run(fmu_dir, tmp_path, capsys):
    scenario = dataclasses.replace(load_scenario(resolve_scenarios(["heavy-pi"])[0]), stop_time_s=1.0)
    system = closed_loop(scenario, fmu_dir)
    plant = system.component("plant")
    broken = dataclasses.replace(plant, parameters={**plant.parameters, "hysteresis_mode": 7})
    components = tuple(broken if c is plant else c for c in system.components)
    path = write_ssp(dataclasses.replace(system, components=components), tmp_path / "bogus.ssp")
    (tmp_path / "not-an-fmu.fmu").write_text("plain text")
    assert main(["check", str(path), str(tmp_path / "not-an-fmu.fmu")]) == 1
    lines = capsys.readouterr().out.splitlines()
    assert any(line.startswith(f"FAIL  {path}: C host (libcosim): ") for line in lines)
    assert f"FAIL  {tmp_path / 'not-an-fmu.fmu'}: archive: not a zip archive (an FMU or SSP is one)" in lines
    assert main(["check", str(tmp_path / "missing.ssp")]) == 2
    assert "missing.ssp: no such file" in capsys.readouterr().err



def test_check_names_a_zip_that_is_no_fmu_or_ssp(tmp_path, capsys):
    """A zip archive without modelDescription.xml (a wheel, say) or an .ssp without
    SystemStructure.ssd: one FAIL line saying so, no check reads further, no traceback."""
    import zipfile
    wheel, package = tmp_path / "some.whl", tmp_path / "empty.ssp"
    for path in (wheel, package):
        with zipfile.ZipFile(path, "w") as archive:
            archive.writestr("module/__init__.py", "")
    assert main(["check", str(wheel), str(package)]) == 1
    captured = capsys.readouterr()
    assert captured.out.splitlines() == [
        f"FAIL  {wheel}: archive: not an FMU: no modelDescription.xml at the top of the archive",
        f"FAIL  {package}: archive: not an SSP package: no SystemStructure.ssd at the top of the archive",
        "check: 2 files, 2 checks: 2 FAIL"]
    assert captured.err == ""
