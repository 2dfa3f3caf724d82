"""The data range of a fitted wire (validity.T_data_min ... stress_data_max) in the C runtime
equals the Python runtime: the plant and the compensator give the same outputs and the same
warnings, bit for bit and word for word, on random walks that leave the range; each warns
about the data range exactly once (the first step outside it, the start included); a wire
without a data range warns as before; a range whose bounds cross is refused alike."""
import random

import pytest

from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.parameters import WireParameters
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.validity import DATA_RANGE_NOTE

import c_feedforward
import c_plant
from c_plant import CPlant, normalized, power_of, power_walk, refusal, same

# the Flexinol data's range (tests/identification: 30-140 degC, 50-200 MPa)
RANGE = dict(T_data_min=30.0, T_data_max=140.0, stress_data_min=50.0, stress_data_max=200.0)
STEPS = 3000


@pytest.fixture(scope="module")
def plant_lib(tmp_path_factory):
    return c_plant.load_library(tmp_path_factory.mktemp("c_plant_range"))


@pytest.fixture(scope="module")
def ff_lib(tmp_path_factory):
    return c_feedforward.load_library(tmp_path_factory.mktemp("c_ff_range"))


def _data_warnings(warnings):
    return [w for w in warnings if w is not None and DATA_RANGE_NOTE in w]


@pytest.mark.parametrize("seed, changes, T_start, load", [
    (41, RANGE, None, 0.0),                                   # starts outside (T_room 10 degC)
    (42, RANGE, 60.0, 0.15),                                  # starts inside, leaves later
    (43, dict(T_data_max=90.0), 60.0, 0.15),                  # one bound only
    (44, dict(stress_data_min=20.0, stress_data_max=60.0), 50.0, 0.05),
])
def test_the_c_plant_warns_as_python_once(plant_lib, params, seed, changes, T_start, load):
    wire = params.replace(**changes)
    rng = random.Random(seed)
    python = PlantStepper(wire, T_start, "continuous", load)
    c = CPlant(plant_lib, wire, T_start, "continuous", load)
    assert same(c.outputs, tuple(python.outputs)) and c.warning == python.warning
    warnings = [python.warning]
    for instruction in power_walk(rng, wire, STEPS):
        sample = power_of(instruction, python)
        assert same(c.step(*sample), tuple(python.step(*sample)))
        assert c.warning == python.warning, sample
        warnings.append(python.warning)
    found = _data_warnings(warnings)
    assert len(found) == 1, found
    first = found[0]
    assert "validity.T_data" in first or "validity.stress_data" in first
    if T_start is None:
        assert warnings[0] == first and "T = 10 degC is below validity.T_data_min = 30 degC" in first


def test_a_wire_without_a_data_range_never_warns_about_one(plant_lib, params):
    rng = random.Random(45)
    python, c = PlantStepper(params), CPlant(plant_lib, params)
    for instruction in power_walk(rng, params, STEPS):
        sample = power_of(instruction, python)
        python.step(*sample), c.step(*sample)
        assert c.warning == python.warning
        assert not _data_warnings([python.warning])


@pytest.mark.parametrize("seed, adapt", [(51, True), (52, False)])
def test_the_c_compensator_warns_as_python_once(ff_lib, params, seed, adapt):
    wire = params.replace(**RANGE)
    rng = random.Random(seed)
    cparams = c_feedforward.CParameters(ff_lib, wire)
    python = FeedforwardStepper(wire, adapt_to_load=adapt)
    c = c_feedforward.CStepper(ff_lib, cparams, wire, adapt_to_load=adapt)
    warnings = []
    for sample in c_feedforward.reference_walk(rng, wire, STEPS):
        assert c.step(*sample) == tuple(python.step(*sample))
        # normalized: the unconnected start's R_ref is %.17g in C, repr in Python
        assert (c.warning and normalized(c.warning)) == \
            (python.warning and normalized(python.warning)), sample
        warnings.append(python.warning)
    found = _data_warnings(warnings)
    assert len(found) == 1 and ("T_ref = " in found[0] or "load = " in found[0]), found


@pytest.mark.parametrize("changes, named", [
    (dict(T_data_min=150.0, T_data_max=140.0), "validity.T_data_min = 150.0 degC"),
    (dict(stress_data_min=210.0, stress_data_max=200.0), "validity.stress_data_min = 210.0 MPa"),
    (dict(stress_data_min=-1.0), "validity.stress_data_min = -1.0"),
    (dict(T_data_max=float("inf")), "validity.T_data_max = inf"),
])
def test_a_bad_data_range_is_refused_alike(plant_lib, params, changes, named):
    values = {**params.values(), **changes}
    source = "SmaActuator instance 'range'"
    message = refusal(lambda: WireParameters.from_values(values, source=source))
    assert message.startswith(source) and named in message
    assert normalized(refusal(lambda: c_plant.CParameters(plant_lib, values, source))) == \
        normalized(message)
