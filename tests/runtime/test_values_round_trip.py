"""Every number the package writes and reads back again comes back bit for bit (issue 32).

Parameter files, the FMUs' modelDescription start values, SSP/export start texts, JSON
reports, measurement CSVs and saved FMU states. The values are doubles that need 17
significant digits, so a writer that rounds to 16 (pythonfmu writes Real starts with
``.16g``) fails here on any Python, not only where a fit happens to land on such a value.
"""
import json
import math

import numpy as np
import pytest
from fmpy import read_model_description

from sma_fmu.fmi.packaging.build import build_fmu
from sma_fmu.fmi.python_family.slave_support.saved_state import split_state, state_from_bytes, state_to_bytes, state_with
from sma_fmu.fmi.python_family.slave_support.start_values import parse_start_value, start_value_text
from sma_fmu.files.json_output import json_text
from sma_fmu.identification.measurements import read_constant_load
from sma_fmu.identification.synthetic import write_rows
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.wire.parameter_file import load_parameter_set, write_parameter_file


def _needs_17_digits(value):
    return float(f"{value:.16g}") != value


def _awkward(value, ulps=64):
    """The nearest double at or above ``value`` that 16 significant digits do not reproduce,
    within ``ulps`` steps; None if there is none (in [64, 100), say, 16 digits are enough)."""
    for _ in range(ulps):
        if _needs_17_digits(value):
            return value
        value = math.nextafter(value, math.inf)
    return None


AWKWARD = [_awkward(x) for x in (59.713553341652535, 0.05, 1e-3, 2.5e-23, 273.15, 1234567.891)]


@pytest.fixture(scope="module")
def awkward_file(parameter_set, tmp_path_factory):
    """A parameter file whose every float parameter was moved to an awkward neighbour."""
    params = parameter_set.params
    moved = {name: _awkward(getattr(params, name)) for name in parameter_set.meanings
             if type(getattr(params, name)) is float}
    moved = {name: value for name, value in moved.items() if value is not None}
    assert len(moved) >= 20 and None not in AWKWARD
    path = tmp_path_factory.mktemp("awkward") / "awkward.toml"
    return write_parameter_file(path, params.replace(**moved), "awkward", "", parameter_set.meanings), moved


def test_the_values_defeat_sixteen_digits(awkward_file):
    _, moved = awkward_file
    assert all(_needs_17_digits(v) for v in [*AWKWARD, *moved.values()])


def test_a_parameter_file_reloads_every_value_exactly(awkward_file):
    path, moved = awkward_file
    params = load_parameter_set(path).params
    assert {name: getattr(params, name) for name in moved} == moved


@pytest.mark.parametrize("model", ["SmaActuator", "SmaFeedforward"])
def test_an_fmus_start_values_are_the_parameter_files_values(awkward_file, tmp_path, model):
    path, moved = awkward_file
    fmu = build_fmu(model, tmp_path, path)
    starts = {v.name: v.start for v in read_model_description(str(fmu)).modelVariables
              if v.type == "Real" and v.name in moved}
    assert len(starts) >= 10
    assert {name: float(text) for name, text in starts.items()} == {n: moved[n] for n in starts}


@pytest.mark.parametrize("value", AWKWARD)
def test_export_start_texts_read_back_exactly(value):
    """The text of SSP parameter bindings and of start values packed by ``sma-fmu export``."""
    assert parse_start_value("Real", start_value_text("Real", value)) == value
    assert parse_start_value("Real", start_value_text("Real", np.float64(value))) == value


def test_json_reports_read_back_exactly():
    document = {"plain": AWKWARD, "numpy": [np.float64(v) for v in AWKWARD],
                "nested": {"ci95": AWKWARD[:2], "value": np.float64(AWKWARD[2])}}
    back = json.loads(json_text(document))
    assert back["plain"] == AWKWARD and back["numpy"] == AWKWARD
    assert back["nested"] == {"ci95": AWKWARD[:2], "value": AWKWARD[2]}


def test_a_measurement_csv_reads_back_exactly(tmp_path):
    temperatures = [_awkward(20.0 + 3.7 * i) for i in range(12)]
    loads = [_awkward(0.05), _awkward(0.15)] * 6
    resistances = [_awkward(49.0 - 0.31 * i) for i in range(12)]
    rows = [{"temperature_C": t, "load_kg": m, "resistance_ohm": r, "direction": "heating"}
            for t, m, r in zip(temperatures, loads, resistances)]
    data = read_constant_load([write_rows(tmp_path / "sweep.csv", rows)])
    assert data.temperature.tolist() == temperatures
    assert data.load.tolist() == loads
    assert data.resistance.tolist() == resistances


def test_a_saved_state_reads_back_exactly(params):
    stepper = PlantStepper(params, load=AWKWARD[1])
    for k in range(200):
        stepper.step(2.0 + 0.5 * math.sin(k / 7.0), AWKWARD[1], 0.01)
    state = state_with({"P_in": AWKWARD[0], "load": AWKWARD[1]}, stepper)
    back = state_from_bytes(state_to_bytes(state))
    assert back == state
    variables, stepper_state = split_state(back)
    assert variables == {"P_in": AWKWARD[0], "load": AWKWARD[1]}
    assert stepper_state == stepper.state()
