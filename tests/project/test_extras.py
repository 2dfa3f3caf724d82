"""The install: the main job needs no extra, every extra of sma_fmu/console/extras.py is
pyproject.toml's, and a command that needs a missing one names it in one line."""
import subprocess
import sys
import textwrap
import tomllib
from pathlib import Path

import pytest

from cli_failure import fails
from sma_fmu.console import extras
from sma_fmu.files.package_data import shipped_file

PYPROJECT = Path(__file__).parents[2] / "pyproject.toml"
MAIN_JOB = {"numpy", "fmpy", "pythonfmu", "matplotlib", "tqdm"}
# what no module of the main job may import (each is an extra's)
OPTIONAL = ("scipy", "pandas", "pyarrow", "dask", "distributed", "threadpoolctl", "openpyxl",
            "fmu_manipulation_toolbox", "libcosimpy")


def _name(requirement):
    return requirement.split(";")[0].split("[")[0].split(">")[0].split("=")[0].split("<")[0].strip().lower()


def _project():
    return tomllib.loads(PYPROJECT.read_text(encoding="utf-8"))["project"]


def test_the_main_job_depends_on_five_packages_and_no_build_tool():
    names = {_name(r) for r in _project()["dependencies"]}
    assert names == MAIN_JOB
    assert not names & {"ziglang", "cmake", "pytest", "scipy", "pyarrow", "pandas"}


def test_every_extra_of_the_table_is_the_pyproject_one():
    optional = _project()["optional-dependencies"]
    for extra, modules in extras.EXTRAS.items():
        assert {_name(r) for r in optional[extra]} == {distribution for _, distribution in modules
                                                       if distribution != "distributed"} \
            | ({"dask"} if extra == "studies" else set()), extra
    assert optional["all"] == [f"sma-fmu[{','.join(extras.EXTRAS)}]"]
    assert "sma-fmu[all]" in optional["test"]


def test_a_missing_module_names_its_extra(monkeypatch):
    monkeypatch.setitem(extras.EXTRAS, "demo", (("no_such_module_sma_fmu", "no-such-package"),))
    assert extras.missing("demo") == ["no-such-package"]
    with pytest.raises(extras.MissingExtra, match=r'^--demo needs no-such-package: pip install '
                                                  r'"sma-fmu\[demo\]"$'):
        extras.require("demo", "--demo")
    assert extras.extra_of_module("pyarrow") == "parquet" and extras.extra_of_module("os") is None


@pytest.mark.parametrize("argv, blocked, expected", [
    (["fit", "constant-load", "{example}"], "scipy", 'fit needs scipy: pip install "sma-fmu[fit]"'),
    (["run", "heavy-pi", "--path", "library", "--format", "parquet"], "pyarrow",
     '--format parquet needs pyarrow: pip install "sma-fmu[parquet]"'),
    (["tune", "heavy-pi"], "pandas", 'tune needs pandas: pip install "sma-fmu[studies]"'),
    (["run", "heavy-pi", "--path", "container"], "fmu_manipulation_toolbox",
     '--path container needs fmu-manipulation-toolbox: pip install "sma-fmu[systems]"'),
])
def test_a_command_without_its_extra_says_which_to_install(capsys, monkeypatch, tmp_path, argv,
                                                           blocked, expected):
    monkeypatch.setitem(sys.modules, blocked, None)   # as if not installed: find_spec says None
    example = str(shipped_file("examples", "constant_load.csv"))
    argv = [part.format(example=example) for part in argv] + ["--out", str(tmp_path / "out")]
    fails(capsys, argv, expected)
    assert not (tmp_path / "out").exists()


def test_the_main_job_runs_without_any_optional_package(tmp_path):
    """A scenario through the library path, its files and figures, in a Python where every
    optional package fails to import (the FMU path is .ci/run's, in the wheel's venv)."""
    code = textwrap.dedent(f"""
        import sys
        class Blocked:
            def find_spec(self, name, path=None, target=None):
                if name.split(".")[0] in {OPTIONAL!r}:
                    raise ModuleNotFoundError(f"blocked: {{name}}", name=name)
        sys.meta_path.insert(0, Blocked())
        from sma_fmu.cli import main
        status = main(["run", "heavy-pi", "--path", "library", "--figures",
                       "--out", {str(tmp_path / 'out')!r}])
        print("imported:", sorted(m for m in sys.modules if m.split(".")[0] in {OPTIONAL!r}))
        sys.exit(status)
    """)
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-3000:]
    assert "imported: []" in result.stdout
    assert (tmp_path / "out" / "heavy-pi" / "figure.png").is_file()
    assert (tmp_path / "out" / "comparison.md").is_file()


def test_the_command_line_starts_without_the_work_imports():
    """``--version``, building the parser and a missing input file import nothing of the
    work (numpy, fmpy, matplotlib...): they answer at once."""
    code = textwrap.dedent("""
        import sys
        from sma_fmu.cli import build_parser, main
        build_parser()
        status = main(["fit", "constant-load", "no-such-file.csv"])
        heavy = sorted(m for m in ("numpy", "fmpy", "matplotlib", "scipy", "pandas", "tomllib")
                       if m in sys.modules)
        print("heavy:", heavy, "status:", status)
    """)
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert "heavy: [] status: 2" in result.stdout, result.stdout + result.stderr
    assert result.stderr.strip() == "sma-fmu: error: no-such-file.csv: file not found"
