"""The worked examples in sma_fmu/examples/ run, and give what the library gives."""
import ast
import csv
import dataclasses
import subprocess
import sys

import numpy as np
import pytest

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.package_data import shipped_file


def _imports(path):
    roots = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            roots |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0:
            roots.add(node.module.split(".")[0])
    return roots


def test_fmpy_loop_example_uses_plain_fmpy_and_matches_the_library(tmp_path, fmus):
    script = shipped_file("examples", "fmpy_closed_loop.py")
    assert "sma_fmu" not in _imports(script) and "fmpy" in _imports(script)
    out = tmp_path / "run.csv"
    result = subprocess.run([sys.executable, str(script), str(fmus["SmaActuator"].parent),
                             "--stop", "6", "--csv", str(out)],
                            capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert result.returncode == 0, result.stderr
    with open(out, newline="") as stream:
        rows = list(csv.DictReader(stream))
    scenario = load_scenario(shipped_file("scenarios", "heavy-continuous-pi+ff-adaptive.toml"))
    library = run_library(dataclasses.replace(scenario, stop_time_s=6.0)).data
    assert len(rows) == len(library) == 6001
    np.testing.assert_allclose([float(r["R_ohm"]) for r in rows], library["R"], rtol=0, atol=1e-9)
    np.testing.assert_allclose([float(r["P_W"]) for r in rows[:-1]], library["P"][:-1],
                               rtol=0, atol=1e-9)
    rmse = float(result.stdout.split(":")[1].split()[0])
    error = library["R"] - library["R_ref"]
    assert rmse == pytest.approx(np.sqrt(np.mean(error[library["t"] >= 2.0 - 1e-9] ** 2)), abs=1e-6)
