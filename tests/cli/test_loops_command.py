"""``sma-fmu loops``: the plant swept through a temperature history, drawn as R over T.

The CSV must show the two properties of spec section 6 (return-point memory, wiping out) and
stay between the major branches of section 4; bad input fails in one line and leaves --out alone.
"""
import csv

import pytest

from cli_failure import fails
from sma_fmu.runtime.thermal import power_to_reach
from sma_fmu.cli import main
from sma_fmu.files.output_folder import MARKER
from sma_fmu.wire.parameter_file import write_parameter_file
from sma_fmu.runtime.constant_load import constant_load_resistance
from sma_fmu.runtime.thermal import step_decay, thermal_step

TOLERANCE_OHM = 1e-9

# (arguments, load [kg], the loops that close: (T [degC] where each began, direction there))
CASES = {
    "default": ([], 0.05, [(60.0, "cooling"), (56.0, "cooling"), (52.0, "cooling")]),
    "heavy": (["--load", "0.25", "--history", "20,150,60,90,70,80,150", "--step-K", "0.2"], 0.25,
              [(90.0, "heating"), (150.0, "heating")]),
}


def _read(path):
    with open(path, newline="", encoding="utf-8") as stream:
        rows = list(csv.DictReader(stream))
    return ([float(r["T_degC"]) for r in rows], [float(r["R_ohm"]) for r in rows],
            [r["direction"] for r in rows], [int(r["stack_depth"]) for r in rows])


def _extrapolate(xs, ys, x):
    """The parabola through three points (xs, ys), evaluated at x (Lagrange)."""
    total = 0.0
    for i, (xi, yi) in enumerate(zip(xs, ys)):
        weight = 1.0
        for k, xk in enumerate(xs):
            if k != i:
                weight *= (x - xk) / (xi - xk)
        total += weight * yi
    return total


@pytest.fixture(scope="module", params=sorted(CASES))
def run(request, tmp_path_factory):
    """Run the command once per case: (case name, load, output folder)."""
    arguments, load, _ = CASES[request.param]
    out = tmp_path_factory.mktemp(request.param) / "loops"
    status = main(["loops", *arguments, "--out", str(out)])
    assert status == 0
    return request.param, load, out


def test_writes_the_csv_and_the_figure(tmp_path, capsys):
    out = tmp_path / "loops"
    assert main(["loops", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert str(out / "loops.csv") in printed and str(out / "loops.png") in printed
    assert sorted(p.name for p in out.iterdir()) == sorted([MARKER, "loops.csv", "loops.png"])
    assert (out / "loops.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (out / "loops.png").stat().st_size > 20_000
    T, R, direction, depth = _read(out / "loops.csv")
    assert (T[0], T[-1], max(T)) == (20.0, 20.0, pytest.approx(120.0, abs=1e-9))
    assert set(direction) == {"heating", "cooling"} and max(depth) >= 4 and depth[-1] == 1


def test_minor_loops_close_where_they_began(run):
    """Return-point memory: when the wire comes back to a reversal point, moving the way it moved
    into it, R is R of that point (within 1e-9 ohm), the branch it came along leads there (its
    last three samples extrapolate to that R within 1e-3 ohm; the test's step is 0.1-0.2 K), and
    the loop's two points are wiped out."""
    name, load, out = run
    T, R, direction, depth = _read(out / "loops.csv")
    reversals = [k for k in range(len(T) - 1) if direction[k + 1] != direction[k]]
    closed = []
    for start, arrival in CASES[name][2]:
        r = next(k for k in reversals if abs(T[k] - start) <= 1e-9 and direction[k] == arrival)
        j = next(k for k in range(r + 2, len(T))
                 if abs(T[k] - start) <= 1e-9 and direction[k] == arrival)
        assert abs(R[j] - R[r]) <= TOLERANCE_OHM, (start, R[j], R[r])
        # the branch runs into the start; it does not jump there when the loop is wiped out
        assert abs(_extrapolate(T[j - 3:j], R[j - 3:j], T[j]) - R[r]) <= 1e-3, start
        assert depth[r + 1] >= depth[r] + 1 and depth[r] in depth[j:j + 2], (start, depth[r:j + 2])
        # and the loop did something: R left its start by more than 0.5 ohm in between
        assert max(abs(R[k] - R[r]) for k in range(r, j)) > 0.5, start
        closed.append(start)
    assert closed == [start for start, _ in CASES[name][2]]


def test_curve_lies_between_the_major_branches(run, params):
    name, load, out = run
    T, R, _, _ = _read(out / "loops.csv")
    inside = 0
    for t, r in zip(T, R):
        heating = constant_load_resistance(t, load, "heating", params)
        cooling = constant_load_resistance(t, load, "cooling", params)
        low, high = min(heating, cooling), max(heating, cooling)
        assert low - TOLERANCE_OHM <= r <= high + TOLERANCE_OHM, (t, r, low, high)
        inside += min(r - low, high - r) > 1.0
    assert inside > 100  # the minor loops run well inside the major loop, not along it


def test_power_lands_the_thermal_model_on_the_target(params):
    decay = step_decay(20.0 * params.tau_th, params.tau_th)
    for start, target in [(20.0, 20.1), (120.0, 119.9), (52.0, 76.0), (74.0, 10.5)]:
        power = power_to_reach(start, target, params.T_room, params.K_th, decay)
        assert power >= 0.0
        landed = thermal_step(start, power, params.T_room, params.K_th, decay)
        assert landed == pytest.approx(target, abs=1e-12)


def _model_with_positive_x_T(tmp_path, params):
    """A wire whose dH(f) falls with the load (x_T > 0): dH <= 0 above ~6 kg."""
    path = tmp_path / "positive-x_T.toml"
    write_parameter_file(path, params.replace(l_M=0.70, l_F=0.80), "positive-x_T")
    return str(path)


# case: (arguments, what the error line must contain); "WIRE" stands for a wire with x_T > 0
BAD = {
    "non-numeric history": (["--history", "20,abc,60"], ["--history", "20,abc,60"]),
    "one point": (["--history", "20"], ["--history 20:", "two turning points"]),
    "below room": (["--history", "20,80,5"], ["--history 20,80,5:", "point 3", "T_room"]),
    "above T_max": (["--history", "20,350"], ["--history 20,350:", "T_max"]),
    "negative load": (["--load", "-0.1"], ["--load", "-0.1"]),
    "load above range": (["--load", "3"], ["--load 3:", "T_max"]),
    "load with dH <= 0": (["--model", "WIRE", "--load", "10"], ["--load 10:", "dH(f)"]),
    "unknown model": (["--model", "no-such-wire.toml"],
                      ["--model no-such-wire.toml:", "parameter file not found"]),
    "step below the minimum": (["--step-K", "1e-9"], ["--step-K 1e-09:", ">= 1e-06 K"]),
    "too many steps": (["--step-K", "1e-5"], ["--step-K 1e-05:", "1,000,000 steps"]),
}


@pytest.mark.parametrize("case", sorted(BAD))
@pytest.mark.parametrize("existing", [True, False], ids=["out-exists", "no-out"])
def test_bad_input_fails_in_one_line_and_leaves_out_alone(case, existing, tmp_path, capsys, params):
    arguments, parts = BAD[case]
    if "WIRE" in arguments:
        arguments = [_model_with_positive_x_T(tmp_path, params) if a == "WIRE" else a
                     for a in arguments]
    argv = ["loops", *arguments]
    work = tmp_path / "work"
    work.mkdir()
    out = work / "loops"
    if existing:
        out.mkdir()
        (out / "loops.csv").write_text("kept\n")
    before = sorted((p.relative_to(work), p.read_bytes() if p.is_file() else None)
                    for p in work.rglob("*"))
    fails(capsys, [*argv, "--out", str(out)], *parts)
    after = sorted((p.relative_to(work), p.read_bytes() if p.is_file() else None)
                   for p in work.rglob("*"))
    assert after == before
