"""fmusim v0.0.39 and a small FMI Library 3.0.4 host run the five FMI 3.0 FMUs of the C
family (``sma-fmu build --native --fmi 3``): by hand, not in CI.

Neither host is in a package registry, so CI cannot have them, and pytest does not collect
this file by default (it does not match test_*.py). docs/systems.md, "FMI 3.0 hosts built by
hand", says how to build fmusim and the FMI Library from their repositories and how to
compile tests/support/fmil3_host.c; then:

    SMA_FMU_FMUSIM=/path/to/fmusim SMA_FMU_FMIL3_HOST=/path/to/fmil3_host \\
        python -m pytest -s tests/hosts/fmi3_hosts_check.py

fmusim: each FMU runs 2 s of co-simulation at 1 ms with the inputs of
tests/hosts/test_native_hosts.py from a CSV file, FMU logging and FMI-call logging on, once plain
and once with ``--event-mode-used --early-return-allowed``: exit status 0, no call returning
Discard, Error or Fatal, no [Error]/[Fatal] message, and the plain run equal to fmpy's
``simulate_fmu`` of the same FMU with the same inputs and step to 1e-12 of each output's
scale (the largest difference is printed).

fmil3_host: each FMU runs 1 s at 1 ms with constant inputs, plain and with event mode and
early return: every FMI call returns OK, the FMU logs no error, and the outputs equal fmpy's
``simulate_fmu`` with the same inputs set as start values to 1e-12 of scale. The FMI
Library 3.0.4's XML parser logs error lines for the plant, each for XML that the FMI 3.0
schemas require (fmpy's ``validate_fmu`` gives [], fmusim validates against the same
schemas): in its terminalsAndIcons.xml, the Terminal and TerminalMemberVariable attributes
``matchingRule``, ``terminalKind``, ``variableName``, ``memberName``, ``variableKind`` (the
library knows only ``name`` and ``description``). The check accepts exactly those lines for
the plant (so the host exits 1 there) and fails on any other error line; the other four
must exit 0 with no error line. (The platforms table moved from a top-level
``<Annotations>``, which the library also refused, to extra/org.sma-fmu.platforms/.)
Without either variable the check fails (it never skips).
"""
import re
import subprocess

import numpy as np
import pytest
from fmpy import simulate_fmu

from fmusim_check import _run as _fmusim  # the same run as the FMI 2.0 check
from system_needs import by_hand_executable
from test_native_hosts import INPUTS, STOP_S, _input

BAD_CALL = re.compile(r"-> (Discard|Error|Fatal|Unknown status)")
BAD_MESSAGE = re.compile(r"^\[(Discard|Error|Fatal)\]")
# the FMI Library 3.0.4 parser's error lines for schema-valid XML (see the docstring)
FMIL_KNOWN = re.compile(
    r"^\[FMIL ERROR\] FMI3XML: Unknown attribute '(matchingRule|terminalKind|variableName|"
    r"memberName|variableKind)=[^']*' in XML$")
SUMMARY = re.compile(r"^fmil3_host: (\w+): (\d+) steps to (\S+) s, (\d+) event\(s\), (\d+) early "
                     r"return\(s\), (\d+) warning line\(s\), (\d+) error line\(s\) \((\d+) from the FMI Library\)$")
CONSTANTS = {  # constant inputs for the FMI Library host, moving each model
    "SmaActuator": {"P_in": 2.0, "load": 0.05},
    "SmaFeedforward": {"R_ref": 42.0, "load": 0.05},
    "SmaPiController": {"R_ref": 42.0, "R": 43.0, "P_ff": 1.0},
    "SmaPwmDriver": {"P_demand": 3.0},
    "SmaScenarioSignals": {},
}


@pytest.fixture(scope="module")
def fmil3_host():
    return by_hand_executable("SMA_FMU_FMIL3_HOST",
                              "tests/support/fmil3_host.c built on the FMI Library 3.0.4")


def _largest(table, expected, names):
    """(largest |difference| / scale, output) over ``names``, scale = max |fmpy's value|."""
    worst = (0.0, "-")
    for name in names:
        if np.ndim(expected[name]) > 1:  # an array output (the plant's reversal stack)
            continue
        ours = np.asarray(expected[name], float)
        scale = max(np.max(np.abs(ours)), 1e-300)
        difference = float(np.max(np.abs(np.asarray(table[name], float) - ours))) / scale
        if difference > worst[0]:
            worst = (difference, name)
    return worst


@pytest.mark.parametrize("model", list(INPUTS))
def test_fmusim_runs_each_fmi3_fmu_clean_and_as_fmpy(fmusim, fmi3_fmus, model, tmp_path):
    path = fmi3_fmus[model]
    code, bad, output, count = _fmusim(fmusim, path, model, tmp_path)
    events = _fmusim(fmusim, path, model, tmp_path, "--event-mode-used", "--early-return-allowed")
    table = np.genfromtxt(output, delimiter=",", names=True)
    expected = simulate_fmu(str(path), stop_time=STOP_S, step_size=1e-3, output_interval=1e-3,
                            input=_input(model, path))
    names = [n for n in table.dtype.names if n != "time" and n in expected.dtype.names]
    worst, name = _largest(table, expected, names)
    print(f"\nfmusim {model} (FMI 3.0): exit {code}, {count}, {len(bad)} bad; with event mode and"
          f" early return: exit {events[0]}, {events[3]}, {len(events[1])} bad; largest difference"
          f" from fmpy {worst:.3g} of scale ({name}), {table.size} rows")
    assert code == 0 and bad == [] and events[0] == 0 and events[1] == []
    assert table.size == expected.size and worst <= 1e-12


def _fmil3(host, path, model, folder, *options):
    output = folder / f"{model}{'-'.join(options)}_fmil3.csv"
    sets = [word for name, value in CONSTANTS[model].items() for word in ("--set", name, repr(value))]
    result = subprocess.run([host, str(path), "--stop", "1", "--step", "0.001", *options, *sets,
                             "--output-file", str(output)], capture_output=True, text=True, timeout=600)
    lines = result.stdout.splitlines()
    summary = SUMMARY.match(lines[-1]) if lines else None
    assert summary, result.stdout + result.stderr
    errors = [line for line in lines if "Error" in line or "ERROR" in line or "Fatal" in line]
    unknown = [line for line in errors if not FMIL_KNOWN.match(line)]
    return result.returncode, summary, errors, unknown, output


@pytest.mark.parametrize("model", list(INPUTS))
def test_fmil3_host_runs_each_fmi3_fmu(fmil3_host, fmi3_fmus, model, tmp_path):
    path = fmi3_fmus[model]
    expected = simulate_fmu(str(path), stop_time=1.0, step_size=1e-3, output_interval=1e-3,
                            start_values=CONSTANTS[model])
    for options in ((), ("--event-mode",)):
        code, summary, errors, unknown, output = _fmil3(fmil3_host, path, model, tmp_path, *options)
        table = np.genfromtxt(output, delimiter=",", names=True)
        names = [n for n in table.dtype.names if n != "time"]
        worst, name = _largest(table, expected, names) if table.size == expected.size else (np.inf, "rows")
        print(f"\nfmil3_host {model} {' '.join(options) or '(plain)'}: exit {code}, "
              f"{summary.group(2)} steps, {summary.group(4)} events, {summary.group(5)} early "
              f"returns, {summary.group(6)} warning lines, {summary.group(7)} error lines "
              f"({len(errors) - len(unknown)} of them the FMI Library parser's known ones); "
              f"largest difference from fmpy {worst:.3g} of scale ({name})")
        assert unknown == [] and int(summary.group(7)) == len(errors)
        assert code == (1 if errors else 0) and summary.group(3) == "1"
        assert errors == [] or model == "SmaActuator"  # only the plant has terminals
        if not options:  # with event mode, the PWM driver's rows are those of its events
            assert worst <= 1e-12


def test_both_hosts_take_the_pwm_drivers_early_returns(fmusim, fmil3_host, fmi3_fmus, tmp_path):
    """At 130 Hz (no period is a whole number of 1 ms steps), duty 0.06: with event mode and
    early return, both hosts step to each edge (early returns counted) and run clean."""
    path = fmi3_fmus["SmaPwmDriver"]
    starts = {"frequency_Hz": 130.0, "P_demand": 0.6}
    result = subprocess.run(
        [fmusim, "--interface-type", "cs", "--stop-time", "1", "--output-interval", "0.001",
         "--event-mode-used", "--early-return-allowed", "--logging-on", "--log-fmi-calls",
         *[w for name, value in starts.items() for w in ("--start-value", name, repr(value))],
         "--output-file", str(tmp_path / "fmusim.csv"), str(path)],
        capture_output=True, text=True, timeout=600)
    lines = (result.stdout + result.stderr).splitlines()
    bad = [line for line in lines if BAD_CALL.search(line) or BAD_MESSAGE.match(line)]
    early = sum(1 for line in lines if "earlyReturn=1" in line)
    CONSTANTS["SmaPwmDriver@130Hz"] = starts
    code, summary, errors, unknown, _ = _fmil3(fmil3_host, path, "SmaPwmDriver@130Hz", tmp_path,
                                               "--event-mode")
    print(f"\nPWM at 130 Hz with event mode and early return: fmusim exit {result.returncode}, "
          f"{early} early returns, {len(bad)} bad; fmil3_host exit {code}, {summary.group(2)} "
          f"steps, {summary.group(4)} events, {summary.group(5)} early returns, "
          f"{len(errors) - len(unknown)} known FMI Library parser error lines, {len(unknown)} other")
    assert result.returncode == 0 and bad == [] and early > 200
    assert unknown == [] and int(summary.group(5)) > 200 and summary.group(3) == "1"


@pytest.mark.parametrize("model", list(INPUTS))
def test_fmusim_resumes_each_fmi3_fmu_from_its_serialized_state(fmusim, fmi3_fmus, model, tmp_path):
    """0 to 1 s saving the serialized state (--final-fmu-state-file), then 1 to 2 s from it
    (--initial-fmu-state-file) in a new process: both clean, and the resumed rows exactly
    those of a run 0 to 2 s."""
    starts = [w for name, value in CONSTANTS[model].items() for w in ("--start-value", name, repr(value))]

    def run(name, *options):
        output = tmp_path / f"{name}.csv"
        result = subprocess.run([fmusim, "--interface-type", "cs", "--output-interval", "0.001",
                                 "--logging-on", *starts, *options, "--output-file", str(output),
                                 str(fmi3_fmus[model])], capture_output=True, text=True, timeout=600)
        lines = (result.stdout + result.stderr).splitlines()
        assert result.returncode == 0 and not [l for l in lines if BAD_MESSAGE.match(l)], lines
        return np.genfromtxt(output, delimiter=",", names=True)

    state = tmp_path / "state.bin"
    whole = run("whole", "--stop-time", "2")
    run("first", "--stop-time", "1", "--final-fmu-state-file", str(state))
    resumed = run("resumed", "--start-time", "1", "--stop-time", "2", "--initial-fmu-state-file", str(state))
    tail = whole[-resumed.size:]
    names = [n for n in whole.dtype.names if n != "time"]
    worst, name = _largest(resumed, tail, names)
    print(f"\nfmusim {model}: resumed from its state at 1 s ({state.stat().st_size} bytes), "
          f"largest difference from the whole run {worst:.3g} of scale ({name})")
    # exact: the saved state carries the run's h0, on which SmaScenarioSignals samples
    # (tests/fmus/test_signals_restore_grid.py; before, its R_ref was 6.7e-14 of scale off)
    assert np.allclose(resumed["time"], tail["time"], rtol=0, atol=1e-12) and worst == 0.0
