"""The worked examples in sma_fmu/examples/ run, and give what the library gives."""
import csv
import dataclasses
import subprocess
import sys

import numpy as np
import pytest

from import_roots import imported_roots
from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.files.package_data import shipped_file


def _imports(path):
    return imported_roots(path.read_text())


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


def _run_example(name, *args, cwd):
    script = shipped_file("examples", name)
    result = subprocess.run([sys.executable, str(script), *args], capture_output=True, text=True,
                            cwd=cwd, timeout=300)
    assert result.returncode == 0, result.stderr
    return result.stdout


def test_change_the_wire_example(tmp_path, params):
    out = _run_example("change_the_wire.py", "--length", "0.5", "--out", str(tmp_path), cwd=tmp_path)
    assert "derived mass: density * pi diameter^2/4 * x0" in out and "derived A_s: pi * diameter" in out
    rows = {line.split()[0]: [float(v.rstrip("%")) for v in line.split()[-5:]]
            for line in out.splitlines() if line.startswith(("reference", "0.5"))}
    reference, cut = rows["reference"], rows["0.5"]
    # K_th = 1/(h_c A_s) and A_s grows with the length; tau_th = m c_p/(h_c A_s) does not
    assert cut[0] / reference[0] == pytest.approx(0.8 / 0.5, rel=1e-3)
    assert cut[1] == pytest.approx(reference[1], rel=0.03)
    # the scaled problem tracks about as well, relative to the reference resistance
    assert cut[3] == pytest.approx(reference[3], rel=0.25) and cut[2] < reference[2]


def test_results_api_example(tmp_path):
    out = _run_example("results_api.py", "--stop", "6", "--out", str(tmp_path), cwd=tmp_path)
    ranking = [line.split() for line in out.splitlines()
               if line.strip().startswith("load-step-continuous") and "per load" not in line]
    assert sorted(row[1] for row in ranking) == ["pi", "pi+ff-adaptive", "pi+ff-fixed"]
    rmses = [float(row[2]) for row in ranking]
    assert rmses == sorted(rmses) and ranking[-1][1] == "pi"
    read_back = float(out.split("RMSE ")[-1].split()[0])
    assert read_back == pytest.approx(rmses[0], abs=5e-5)
    assert (tmp_path / "best.png").stat().st_size > 10000
