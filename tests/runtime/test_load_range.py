"""Fuzz leftovers of issue 29: the CLI warns about loads beyond validity as the FMUs do, and a
parameter file whose values together put the model out of range is refused when it is read,
naming the file and the parameters behind it."""
import re
import subprocess
import sys

import pytest

from sma_fmu.files.package_data import default_parameter_file
from sma_fmu.wire.parameter_file import ParameterError, load_parameter_set


def _edited(tmp_path, key, value):
    text = default_parameter_file().read_text(encoding="utf-8")
    text, count = re.subn(rf"(?m)^({key}\s*=\s*\{{ value = )[^,]*", rf"\g<1>{value}", text)
    assert count == 1
    path = tmp_path / f"{key}.toml"
    path.write_text(text, encoding="utf-8")
    return path


# (l_F = 1e308, which gave x_T = -5e+307 m, is now refused by its plausible range when the
# file is read: tests/test_parameter_ranges.py)
@pytest.mark.parametrize("key, value, named", [("mass", "5e-324", "geometry.mass = 5e-324 kg")])
def test_a_file_that_overflows_the_model_names_itself_and_the_parameter(tmp_path, key, value, named):
    path = _edited(tmp_path, key, value)
    with pytest.raises(ParameterError) as caught:
        load_parameter_set(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: the model cannot be evaluated at load")
    assert "dH(f) overflows" in message and named in message


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "sma_fmu", *args], capture_output=True, text=True)


def test_cli_reads_an_overflowing_file_as_one_error_line(tmp_path):
    path = _edited(tmp_path, "mass", "5e-324")
    result = _cli("resistance", "--temperature", "50", "--load", "0.05", "--direction", "heating",
                  "--model", str(path))
    assert result.returncode == 2 and result.stdout == ""
    assert result.stderr.startswith(f"sma-fmu: error: {path}:") and len(result.stderr.splitlines()) == 1


@pytest.mark.parametrize("command", [["sense", "--resistance", "40"], ["resistance", "--temperature", "50"]])
@pytest.mark.parametrize("load", ["100", "1e300"])
def test_cli_warns_about_a_load_beyond_validity_and_still_answers(command, load):
    result = _cli(*command, "--load", load, "--direction", "heating")
    assert result.returncode == 0
    limit = load_parameter_set().params.load_max
    warnings = [line for line in result.stderr.splitlines() if line.startswith("sma-fmu: warning:")]
    assert len(warnings) == 1 and f"{limit:.4g} kg" in warnings[0] and "--load" in warnings[0]


def test_cli_says_nothing_within_validity():
    result = _cli("sense", "--resistance", "40", "--load", "0.05", "--direction", "heating")
    assert result.returncode == 0 and result.stderr == ""
