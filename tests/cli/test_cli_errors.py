"""Every failure of the command line is one line ``sma-fmu: error: ...`` with exit status 2.

Each case here became a traceback or an unclear message once; the message must name the
file, section/key or argument and the value.
"""
import codecs
import shutil
import zipfile

import pytest

from cli_failure import fails as _fails
from sma_fmu.cli import main
from sma_fmu.files.package_data import shipped_file


def _scenario(tmp_path, name="heavy-pi", **replace):
    """A copy of a shipped scenario with lines replaced: {'step_s': 'step_s = 1e-3'}."""
    lines = shipped_file("scenarios", f"{name}.toml").read_text().splitlines()
    for key, line in replace.items():
        matches = [i for i, text in enumerate(lines) if text.startswith(key)]
        if matches:
            lines[matches[0]] = line
        else:
            lines.insert(lines.index("[scenario]") + 1, line)
    path = tmp_path / f"{name}-changed.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


# -- a folder where a file is expected --------------------------------------------------------

def test_folder_given_as_parameter_file(tmp_path, capsys):
    _fails(capsys, ["lattice", "--model", str(tmp_path)], str(tmp_path), "is a folder, not a parameter file")


def test_folder_given_as_scenario_or_csv(tmp_path, capsys):
    folder = tmp_path / "case.toml"
    folder.mkdir()
    _fails(capsys, ["run", str(folder), "--path", "library", "--out", str(tmp_path / "o")],
           str(folder), "is not a file")
    _fails(capsys, ["fit", "constant-load", str(tmp_path), "--out", str(tmp_path / "f")],
           str(tmp_path), "is a folder, not a CSV file")


# -- options: never abbreviated, an unknown one named with the command's closest ---------------

def test_an_option_is_never_taken_for_a_longer_one(tmp_path, capsys, monkeypatch):
    """``run --output DIR`` is not ``--output-interval DIR``: it is unknown, and the error
    names ``--out``; nothing is written."""
    monkeypatch.chdir(tmp_path)
    line = _fails(capsys, ["run", "heavy-pi", "--path", "library", "--output", "out"],
                  "unrecognized arguments: --output out", "did you mean '--out'")
    assert "--output-interval: expected" not in line and not list(tmp_path.iterdir())
    _fails(capsys, ["run", "heavy-pi", "--figure"], "--figure", "'--figures'")
    _fails(capsys, ["fit", "isobaric", "x.csv", "--lodd", "1"], "--lodd", "'--load'")


# -- --out naming an existing file or an unwritable place -------------------------------------

@pytest.mark.parametrize("command", [
    ["build"], ["run", "heavy-pi", "--path", "library"], ["bench", "--runs", "1"],
    ["fit", "constant-load", str(shipped_file("examples", "constant_load.csv"))],
    ["sweep", str(shipped_file("examples", "gain-grid.toml"))],
])
def test_out_is_an_existing_file(tmp_path, capsys, command):
    target = tmp_path / "taken"
    target.write_text("keep me")
    _fails(capsys, command + ["--out", str(target)], f"--out {target}", "exists and is not a folder")
    assert target.read_text() == "keep me"


@pytest.mark.parametrize("command", [
    ["build"], ["run", "heavy-pi", "--path", "library"],
    ["fit", "constant-load", str(shipped_file("examples", "constant_load.csv"))],
    ["synth", "constant-load"],
    ["sweep", str(shipped_file("examples", "gain-grid.toml"))],
])
def test_out_under_a_file_cannot_be_written(tmp_path, capsys, command):
    blocker = tmp_path / "file"
    blocker.write_text("")
    out = blocker / "sub" / "x"
    _fails(capsys, command + ["--out", str(out)], f"--out {out}", f"{blocker} is a file, not a folder")


def test_synth_out_is_a_folder(tmp_path, capsys):
    _fails(capsys, ["synth", "constant-load", "--out", str(tmp_path)], str(tmp_path), "is a folder")


# -- files that are not what they claim to be -------------------------------------------------

@pytest.fixture
def broken_fmus(tmp_path, fmus):
    good = fmus["SmaActuator"].read_bytes()
    files = {"not-zip": tmp_path / "text.fmu", "truncated": tmp_path / "half.fmu",
             "no-description": tmp_path / "empty.fmu"}
    files["not-zip"].write_text("not an archive")
    files["truncated"].write_bytes(good[: len(good) // 2])
    with zipfile.ZipFile(files["no-description"], "w") as archive:
        archive.writestr("resources/x.txt", "x")
    return files


@pytest.mark.parametrize("kind,message", [
    ("not-zip", "not an FMU: not a zip archive"), ("truncated", "not an FMU: not a zip archive"),
    ("no-description", "no modelDescription.xml"),
])
def test_validate_a_broken_fmu(capsys, broken_fmus, kind, message):
    _fails(capsys, ["validate", str(broken_fmus[kind])], str(broken_fmus[kind]), message)


def test_run_finds_a_broken_fmu(tmp_path, capsys, broken_fmus):
    folder = tmp_path / "fmus"
    folder.mkdir()
    shutil.copy(broken_fmus["truncated"], folder / "SmaActuator.fmu")
    _fails(capsys, ["run", "heavy-pi", "--fmus", str(folder), "--out", str(tmp_path / "o")],
           str(folder / "SmaActuator.fmu"), "not a zip archive")


# -- malformed text files ---------------------------------------------------------------------

def test_deeply_nested_toml(tmp_path, capsys):
    deep = tmp_path / "deep.toml"
    deep.write_text("x = " + "[" * 50000 + "]" * 50000 + "\n")
    _fails(capsys, ["lattice", "--model", str(deep)], str(deep), "nested too deeply")
    _fails(capsys, ["run", str(deep), "--path", "library", "--out", str(tmp_path / "o")],
           str(deep), "nested too deeply")


@pytest.mark.parametrize("encoding", ["utf-16", "latin-1"])
def test_toml_not_in_utf8_names_the_file(tmp_path, capsys, encoding):
    text = shipped_file("models", "reference_wire.toml").read_text().replace("reference", "référence")
    path = tmp_path / "wire.toml"
    path.write_bytes(text.encode(encoding))
    _fails(capsys, ["lattice", "--model", str(path)], str(path), "not a UTF-8 text file")


@pytest.fixture
def sweeps():
    return shipped_file("examples", "constant_load.csv").read_text()


@pytest.mark.parametrize("encoding", ["utf-16", "latin-1"])
def test_csv_not_in_utf8_names_the_file(tmp_path, capsys, sweeps, encoding):
    path = tmp_path / "sweeps.csv"
    path.write_bytes(sweeps.replace("temperature_C", "températur_C", 1).encode(encoding))
    _fails(capsys, ["fit", "constant-load", str(path), "--out", str(tmp_path / "f")],
           str(path), "not a UTF-8 text file")


def test_csv_cell_over_128_kib(tmp_path, capsys, sweeps):
    lines = sweeps.splitlines()
    lines[5] += "," + "9" * 140_000
    path = tmp_path / "sweeps.csv"
    path.write_text("\n".join(lines))
    _fails(capsys, ["fit", "constant-load", str(path), "--out", str(tmp_path / "f")],
           str(path), "line 6", "field larger than field limit")


def test_csv_with_a_byte_order_mark_is_read(tmp_path, capsys, sweeps):
    path = tmp_path / "sweeps.csv"
    path.write_bytes(codecs.BOM_UTF8 + sweeps.encode())
    assert main(["fit", "constant-load", str(path), "--out", str(tmp_path / "f")]) == 0
    assert (tmp_path / "f" / "identified.toml").is_file()


# -- parameter values that pass the schema but break derived constants ------------------------

def _wire_with(tmp_path, key, value):
    """The shipped parameter file with ``key``'s value text replaced by ``value``; its path."""
    lines = shipped_file("models", "reference_wire.toml").read_text().splitlines()
    index = next(i for i, line in enumerate(lines) if line.split("=")[0].strip() == key)
    start = lines[index].index("value = ") + len("value = ")
    end = lines[index].index(",", start)
    lines[index] = lines[index][:start] + value + lines[index][end:]
    path = tmp_path / "wire.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("key,value,derived", [
    ("diameter", "5e-324", "lattice"), ("x0", "1e-320", "line density"),
    ("h_c", "1e-320", "thermal gain"), ("A_s", "1e-320", "thermal gain"),
])
def test_parameters_that_break_derived_constants(tmp_path, capsys, key, value, derived):
    path = _wire_with(tmp_path, key, value)
    line = _fails(capsys, ["lattice", "--model", str(path)], str(path), f"derived {derived}")
    assert f".{key} = {float(value)!r}" in line


@pytest.mark.parametrize("key,value,limits", [
    ("diameter", "1e300", "(0, 0.01] [m]"), ("x0", "1e300", "(0, 10] [m]"),
    ("mass", "1e300", "(0, 10] [kg]"),
])
def test_parameters_outside_their_plausible_range(tmp_path, capsys, key, value, limits):
    """Values that used to break only the derived constants (the lattice overflowed) are now
    refused by their plausible range, naming the parameter, its unit and the range."""
    path = _wire_with(tmp_path, key, value)
    line = _fails(capsys, ["lattice", "--model", str(path)], str(path), f"must be in {limits}")
    assert f".{key} = {float(value)!r}" in line


# -- scenario values ----------------------------------------------------------------------------

@pytest.mark.parametrize("replace,parts", [
    ({"model": "model = 3"}, ["[scenario] model must be a string, got 3"]),
    ({"step_s": "step_s = 5e-324"}, ["[scenario] stop_time_s / step_s", "at most 4000000 steps"]),
    ({"stop_time_s": "stop_time_s = 1e5", "step_s": "step_s = 1e-12"},
     ["1e+17 steps", "at most 4000000 steps"]),
    ({"offset_ohm": "offset_ohm = 1e300"}, ["[reference]", "must stay <= 1e+06 ohm", "1e+300"]),
])
def test_bad_scenario_values(tmp_path, capsys, replace, parts):
    path = _scenario(tmp_path, **replace)
    _fails(capsys, ["run", str(path), "--path", "library", "--out", str(tmp_path / "o")],
           str(path), *parts)
    assert not (tmp_path / "o").exists()


def test_analysis_window_outside_the_run(tmp_path, capsys):
    path = _scenario(tmp_path, stop_time_s="stop_time_s = 10.0")
    path.write_text(path.read_text() + "\n[analysis]\nmetrics_start_s = 12.0\n")
    _fails(capsys, ["run", str(path), "--path", "library", "--out", str(tmp_path / "o")],
           str(path), "[analysis] metrics_start_s = 12.0 must be in [0, stop_time_s = 10.0)")


@pytest.mark.parametrize("argv,parts", [
    (["synth", "constant-load", "--t-step", "0"], ["--t-step", "expected a number in (0, 100] K, got '0'"]),
    (["synth", "constant-load", "--noise-ohm", "1e308"], ["--noise-ohm", "in [0, 10] ohm"]),
    (["synth", "constant-load", "--t-step", "1e-9"], ["--t-step 1e-09 K", "at most 1,000,000"]),
    (["synth", "constant-temperature", "--loads", "0,1e300"], ["--loads 1e+300 kg", "validity"]),
    (["synth", "constant-temperature", "--load-step", "1e-9"], ["--load-step 1e-09 kg", "rows"]),
    (["synth", "constant-load", "--t-max", "1e6"], ["--t-max 1000000.0 degC", "(-273.15, 300]"]),
    (["synth", "isobaric", "--points", "1e9"], ["--points", "in [10, 1000000]"]),
    (["fit", "isobaric", "x.csv", "--load", "1e300"], ["--load 1e+300 kg", "[0, 10] kg"]),
    (["fit", "isobaric", "x.csv", "--stress", "0"], ["--stress 0.0 MPa", "(0, 2000] MPa"]),
    (["fit", "isobaric", "x.csv", "--reference-length", "1e9"], ["--reference-length", "(0, 100] m"]),
    (["synth", "constant-temperature", "--load-step", "0"], ["--load-step", "got '0'"]),
    (["bench", "--runs", "0"], ["--runs", "expected a whole number in [1, 1000], got '0'"]),
    (["bench", "--runs", "1001"], ["--runs", "expected a whole number in [1, 1000], got '1001'"]),
    (["tune", "paper", "--generations", "1000000"], ["--generations", "in [1, 1000]"]),
    (["tune", "paper", "--population", "0"], ["--population", "in [1, 100]"]),
    (["tune", "paper", "--seed", "-1"], ["--seed", "in [0, 4294967295]"]),
    (["tune", "paper", "--criterion", "position"], ["--criterion", "invalid choice: 'position'"]),
    (["sweep", "x.toml", "--workers", "100000"], ["--workers", "in [1, 256]"]),
    (["resistance", "--temperature", "1e999", "--load", "0", "--direction", "heating"],
     ["--temperature", "expected a finite number, got '1e999'"]),
    (["no-such-command"], ["invalid choice: 'no-such-command'"]),
])
def test_bad_arguments(tmp_path, capsys, argv, parts):
    _fails(capsys, argv + (["--out", str(tmp_path / "x.csv")] if argv[0] == "synth" else []), *parts)
    assert not (tmp_path / "x.csv").exists()


def test_version(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    from sma_fmu import __version__
    assert capsys.readouterr().out.strip() == f"sma-fmu {__version__}"


@pytest.mark.parametrize("command,default", [
    ("run", "(default: results)"), ("build", "(default: fmus)"), ("bench", "(default: 5)"),
    ("synth", "(default: 0.005)"), ("run", "(default: fmu)"),
])
def test_help_shows_defaults(capsys, command, default):
    with pytest.raises(SystemExit):
        main([command, "--help"])
    assert default in " ".join(capsys.readouterr().out.split())
