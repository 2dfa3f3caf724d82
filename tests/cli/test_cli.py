"""The sma-fmu command line: outputs, JSON, and errors on stderr with a non-zero exit."""
import json
import math

import pytest

from sma_fmu.cli import main


def _json(capsys, argv):
    assert main(argv + ["--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_lattice_json(capsys, params):
    out = _json(capsys, ["lattice"])
    assert out["x_P"] == pytest.approx(params.lattice.x_P, rel=1e-15)
    assert set(out) == {"N", "x_P", "N_l", "N_S"}


def test_resistance_then_sense_round_trips(capsys):
    forward = _json(capsys, ["resistance", "--temperature", "70", "--load", "0.05",
                             "--direction", "heating"])
    assert forward["xi_P"] + forward["xi_M"] + forward["xi_F"] == pytest.approx(1.0, abs=1e-15)
    back = _json(capsys, ["sense", "--resistance", repr(forward["R"]), "--load", "0.05",
                          "--direction", "heating"])
    assert back["T"] == pytest.approx(70.0, abs=1e-9)
    assert back["saturated"] is False


def test_constant_length_text_output(capsys, params):
    assert main(["constant-length", "--xi-p", "0.4391", "--xi-m", "0.2805", "--xi-f", "0.2805"]) == 0
    out = capsys.readouterr().out
    printed = float(out.split("df_dT = ")[1].split()[0])
    # spec section 8, computed here: (df/dT)_x = -N k_B (ln xi_F - ln xi_P / 2 - ln xi_M / 2) / (g x_f)
    slope = (-params.N * 1.380649e-23 * (math.log(0.2805) - 0.5 * math.log(0.4391)
                                          - 0.5 * math.log(0.2805)) / (9.80665 * params.x_f))
    assert printed == pytest.approx(slope, rel=1e-6)
    assert printed == pytest.approx(9.945e-3, rel=2e-3)      # the paper's value


@pytest.mark.parametrize("argv,message", [
    (["resistance", "--temperature", "20", "--load", "-1", "--direction", "heating"],
     "load must be >= 0, got -1.0"),
    (["sense", "--resistance", "40", "--load", "0.1", "--direction", "cooling",
      "--model", "/nonexistent/wire.toml"], "/nonexistent/wire.toml: parameter file not found"),
])
def test_errors_go_to_stderr_with_exit_2(capsys, argv, message):
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert message in captured.err


@pytest.mark.parametrize("argv,message", [
    (["resistance", "--temperature", "nan", "--load", "0", "--direction", "heating"],
     "expected a finite number, got 'nan'"),
    (["sense", "--resistance", "40", "--load", "0.1", "--direction", "up"],
     "direction must be 'heating' (+1) or 'cooling' (-1), got 'up'"),
])
def test_argument_errors_exit_2(capsys, argv, message):
    with pytest.raises(SystemExit) as raised:
        main(argv)
    assert raised.value.code == 2
    assert message in capsys.readouterr().err
