"""fmusim (the Modelica Association's Reference-FMUs simulator) runs every native FMU clean:
by hand, not in CI.

fmusim is in no package registry, so CI cannot have it, and pytest does not collect this file
by default (it does not match test_*.py). Build fmusim of Reference-FMUs v0.0.39 (its
fmusim/ sources with libxml2, zlib, minizip and SUNDIALS' CVODE: Debian's libxml2-dev,
libminizip-dev, libsundials-dev), then:

    SMA_FMU_FMUSIM=/path/to/fmusim python -m pytest tests/hosts/fmusim_check.py

Each native FMU (and the pythonfmu SmaActuator, for comparison) runs 2 s of co-simulation
at 1 ms with the inputs of tests/hosts/test_native_hosts.py from a CSV file, with FMU logging on
and every FMI call logged: exit status 0, no FMI call returning Discard, Error or Fatal, no
[Error]/[Fatal] message, and the result equal to fmpy's run of the same FMU to 1e-12 of each
output's scale (fmusim's communication points differ from fmpy's in the last bit, and so do
the inputs interpolated there: P_fb, a small difference of resistances, then differs by
more than 1e-12 of its own value near zero). Without
SMA_FMU_FMUSIM the check fails (it never skips).
"""
import csv
import re
import subprocess

import numpy as np
import pytest

from test_native_hosts import INPUTS, STOP_S, _simulate, _times

BAD_CALL = re.compile(r"-> (Discard|Error|Fatal|Unknown status)")
BAD_MESSAGE = re.compile(r"^\[(Discard|Error|Fatal)\]")


def _input_file(model, folder):
    values = INPUTS[model](_times())
    if not values:
        return []
    path = folder / f"{model}_in.csv"
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["time", *values])
        for k, t in enumerate(_times()):
            writer.writerow([repr(float(t)), *(repr(float(v[k])) for v in values.values())])
    return ["--input-file", str(path)]


def _run(fmusim, path, model, folder, *options):
    """fmusim over ``path`` (co-simulation, 1 ms, with the model's inputs and ``options``):
    (exit status, bad lines, the output CSV, "N log lines, M warning")."""
    output = folder / f"{model}{'-'.join(options)}_out.csv"
    command = [fmusim, "--interface-type", "cs", "--stop-time", repr(STOP_S), "--output-interval",
               "0.001", "--logging-on", "--log-fmi-calls", *options, *_input_file(model, folder),
               "--output-file", str(output), str(path)]
    result = subprocess.run(command, capture_output=True, text=True, timeout=600)
    lines = (result.stdout + result.stderr).splitlines()
    bad = [line for line in lines if BAD_CALL.search(line) or BAD_MESSAGE.match(line)]
    warnings = sum(1 for line in lines if "-> Warning" in line or line.startswith("[Warning]"))
    return result.returncode, bad, output, f"{len(lines)} log lines, {warnings} warning"


@pytest.mark.parametrize("model", list(INPUTS))
def test_fmusim_runs_each_native_fmu_clean(fmusim, native_fmus, model, tmp_path):
    code, bad, output, count = _run(fmusim, native_fmus[model], model, tmp_path)
    print(f"\nfmusim {model} (native): exit {code}, {count}, {len(bad)} bad")
    assert code == 0 and bad == []
    table = np.genfromtxt(output, delimiter=",", names=True)
    expected, _ = _simulate(native_fmus[model], model)
    assert table.size == expected.size
    for name in table.dtype.names:  # relative to each output's scale: see the docstring
        if name != "time" and name in expected.dtype.names:
            ours = np.asarray(expected[name], float)
            scale = max(np.max(np.abs(ours)), 1e-300)
            assert np.max(np.abs(table[name] - ours)) <= 1e-12 * scale, name


def test_fmusim_runs_the_pythonfmu_plant_clean(fmusim, fmus, tmp_path):
    """For comparison: the pythonfmu SmaActuator in the same host, the same way."""
    code, bad, _, count = _run(fmusim, fmus["SmaActuator"], "SmaActuator", tmp_path)
    print(f"\nfmusim SmaActuator (pythonfmu): exit {code}, {count}, {len(bad)} bad")
    assert code == 0 and bad == []
