"""The FMU Compliance Checker (modelica-tools/FMUComplianceChecker, on the FMI Library 2.0.3)
checks and runs every native FMU clean: by hand, not in CI.

The checker is in no package registry, so CI cannot have it, and pytest does not collect
this file by default (it does not match test_*.py). Build it with its CMake files (the FMI
Library checked out into its FMIL/ folder; CMake 3.x, e.g. Debian's cmake), then:

    SMA_FMU_COMPLIANCE_CHECKER=/path/to/fmuCheck.linux64 \
        python -m pytest tests/hosts/compliance_checker_check.py

Each native FMU (and the pythonfmu SmaActuator, for comparison) is checked as a
co-simulation FMU and simulated 2 s at 1 ms with the inputs of tests/hosts/test_native_hosts.py
(log level 4, info): exit status 0, no [ERROR] or [FATAL] line, and the summary "Checker
reported: 0 Error(s)" with no error the FMU reported. Without SMA_FMU_COMPLIANCE_CHECKER
the check fails (it never skips).
"""
import re
import subprocess

import pytest

from fmusim_check import _input_file
from system_needs import by_hand_executable
from test_native_hosts import INPUTS, STOP_S

BAD_LINE = re.compile(r"^\s*\[(ERROR|FATAL)\]")


@pytest.fixture(scope="module")
def checker():
    """The executable SMA_FMU_COMPLIANCE_CHECKER names; a missing one fails the check."""
    return by_hand_executable("SMA_FMU_COMPLIANCE_CHECKER",
                              "the FMU Compliance Checker (fmuCheck.linux64)")


def _check(checker, path, model, folder):
    """(exit status, bad lines, summary {name: count}, line count) of one checker run."""
    inputs = _input_file(model, folder)
    command = [checker, "-k", "cs", "-h", "0.001", "-s", repr(STOP_S), "-n", "0", "-l", "4",
               "-o", str(folder / f"{model}_out.csv"), "-t", str(folder),
               *(["-i", inputs[1]] if inputs else []), str(path)]
    result = subprocess.run(command, capture_output=True, text=True, timeout=600)
    lines = (result.stdout + result.stderr).splitlines()
    text = "\n".join(lines)
    summary = {
        "checker errors": re.search(r"Checker reported:\s*\n\s*(\d+) Warning\(s\)\s*\n\s*(\d+) Error\(s\)", text),
        "fmu": re.search(r"FMU reported:\s*\n\s*(\d+) warning\(s\) and error\(s\)", text)}
    assert summary["checker errors"] and summary["fmu"], text[-2000:]
    counts = {"checker warnings": int(summary["checker errors"].group(1)),
              "checker errors": int(summary["checker errors"].group(2)),
              "FMU warnings and errors": int(summary["fmu"].group(1))}
    bad = [line for line in lines if BAD_LINE.match(line)]
    return result.returncode, bad, counts, len(lines)


@pytest.mark.parametrize("model", list(INPUTS))
def test_the_compliance_checker_passes_each_native_fmu(checker, native_fmus, model, tmp_path):
    code, bad, counts, count = _check(checker, native_fmus[model], model, tmp_path)
    print(f"\nFMU Compliance Checker {model} (native): exit {code}, {count} lines, {counts}, "
          f"{len(bad)} [ERROR]/[FATAL]")
    assert code == 0 and bad == [] and counts["checker errors"] == 0
    assert (tmp_path / f"{model}_out.csv").stat().st_size > 0


def test_the_compliance_checker_passes_the_pythonfmu_plant(checker, fmus, tmp_path):
    """For comparison: the pythonfmu SmaActuator, checked the same way."""
    code, bad, counts, count = _check(checker, fmus["SmaActuator"], "SmaActuator", tmp_path)
    print(f"\nFMU Compliance Checker SmaActuator (pythonfmu): exit {code}, {count} lines, {counts}, "
          f"{len(bad)} [ERROR]/[FATAL]")
    assert code == 0 and bad == [] and counts["checker errors"] == 0
