"""Saved stepper states are read like inputs: a malformed entry is refused, naming it,
and the stepper is left as it was (issue: edited saved states)."""
import json
import math

import pytest

from sma_fmu.files.package_data import shipped_file

from sma_fmu.runtime import two_stage_root
from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.pi_control import PIController
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.pwm import PwmDriver
from sma_fmu.wire.parameter_file import load_parameter_set

STEP = 1e-3


def _plant(params):
    plant = PlantStepper(params, load=0.05)
    for k in range(3000):
        plant.step(2.2 + math.sin(0.01 * k), 0.05, STEP)
    return plant


def _compensator(params):
    compensator = FeedforwardStepper(params, inverse="minor-loop")
    for reference in (44.0, 40.0, 42.0, 41.0):
        compensator.step(reference, 0.05, STEP)
    return compensator


PLANT_EDITS = [
    ({"xi_P": -5.0}, "xi_P"),
    ({"xi_MF": -5.0}, "xi_MF"),
    ({"xi_MF": 0.5, "xi_P": 0.5}, "must add up to"),
    ({"temperature": 1e308}, "temperature"),
    ({"temperature": -300.0}, "temperature"),
    ({"temperature": "hot"}, "temperature must be a number"),
    ({"direction": 0}, "direction"),
    ({"direction": True}, "direction"),
    ({"load": -1.0}, "load"),
    ({"load": 1e308}, "load"),
    ({"power": float("nan")}, "power"),
    ({"reversals": "none"}, "reversals"),
    ({"reversals": [[60.0, float("inf")]]}, r"reversals\[0\]"),
    ({"extra": 1}, "unknown entry extra"),
]


@pytest.mark.parametrize("edit,words", PLANT_EDITS)
def test_plant_refuses_an_edited_state_and_stays_as_it_was(params, edit, words):
    plant = _plant(params)
    saved, before, outputs = plant.state(), plant.state(), plant.outputs
    with pytest.raises(ValueError, match=words):
        plant.restore({**saved, **edit})
    assert plant.state() == before and plant.outputs == outputs


def test_plant_refuses_a_state_with_a_missing_entry(params):
    plant = _plant(params)
    saved = plant.state()
    del saved["xi_P"]
    with pytest.raises(ValueError, match="lacks entry xi_P"):
        plant.restore(saved)


COMPENSATOR_EDITS = [
    ({"previous_reference": "hot"}, "previous_reference must be a number"),
    ({"previous_reference": -1.0}, "previous_reference"),
    ({"previous_fraction": 2.0}, "previous_fraction"),
    ({"previous_fraction": None}, "both be numbers or both be null"),
    ({"direction": 2}, "direction"),
    ({"filter": {"previous_input": 1.0, "previous_output": None}}, "both be numbers or both"),
    ({"filter": {"previous_input": "x", "previous_output": 1.0}}, "previous_input"),
    ({"reversals": [[60.0, 0.5, 1.0]]}, r"reversals\[0\]"),
    ({"previous_exponent": math.inf, "previous_slope": 1e4}, "previous_exponent"),
    ({"previous_exponent": 0.5, "previous_slope": 0.0}, "previous_slope"),
    ({"previous_exponent": 0.5, "previous_slope": -2e4}, "previous_slope"),
    ({"previous_exponent": 0.5, "previous_slope": "steep"}, "previous_slope must be a number"),
    ({"previous_exponent": 0.5, "previous_slope": None}, "previous_exponent and previous_slope"),
]


@pytest.mark.parametrize("edit,words", COMPENSATOR_EDITS)
def test_compensator_refuses_an_edited_state_and_stays_as_it_was(params, edit, words):
    compensator = _compensator(params)
    saved, before = compensator.state(), compensator.state()
    with pytest.raises(ValueError, match=words):
        compensator.restore({**saved, **edit})
    assert compensator.state() == before
    assert compensator.step(42.5, 0.05, STEP) == _compensator(params).step(42.5, 0.05, STEP)


@pytest.mark.parametrize("block,state,words", [
    (lambda: PIController(0.3, 1.0), {"integral": "x"}, "integral must be a number"),
    (lambda: PIController(0.3, 1.0), {"integral": 1.0, "more": 2}, "unknown entry more"),
    (lambda: PwmDriver(50.0, 2.0), {"held": [1, 2.0], "power": 0.0}, "duty"),
    (lambda: PwmDriver(50.0, 2.0), {"held": None}, "lacks entry power"),
])
def test_control_blocks_refuse_edited_states(block, state, words):
    instance = block()
    before = instance.state()
    with pytest.raises(ValueError, match=words):
        instance.restore(state)
    assert instance.state() == before


def _cosine(stepper, start, count):
    """Step ``stepper`` through the heavy scenario's R_ref (0.25 kg) from step ``start``;
    the outputs."""
    return [stepper.step(41.85 + 6.05 * math.cos(math.pi * k * STEP), 0.25, STEP)
            for k in range(start, start + count)]


def test_a_two_stage_compensators_state_carries_the_search_tangent(monkeypatch):
    """The Flexinol fit (two stages): the saved state holds the search's tangent at the last
    T_ref, and a stepper restored from it (through JSON) takes the next step as the one that
    saved it, to the bit, its state after it included. Restored without the tangent, the
    next search starts at the last root instead: it lands within the search's tolerance
    and needs more evaluations (counted as the exponentials the search takes, two each)."""
    params = load_parameter_set(shipped_file("models", "flexinol_fit.toml")).params
    running = FeedforwardStepper(params)
    _cosine(running, 0, 700)
    exponentials = [0]

    def counted(x):
        exponentials[0] += 1
        return math.exp(x)
    monkeypatch.setattr(two_stage_root, "_exp", counted)
    largest, counts = 0.0, {"tangent": 0, "none": 0}
    for k in range(700, 800):
        saved = json.loads(json.dumps(running.state()))
        assert saved["previous_exponent"] is not None and saved["previous_slope"] > 0.0
        restored, untangent = FeedforwardStepper(params), FeedforwardStepper(params)
        restored.restore(saved)
        untangent.restore({**saved, "previous_exponent": None, "previous_slope": None})
        expected = _cosine(running, k, 1)[0]
        exponentials[0] = 0
        assert _cosine(restored, k, 1)[0] == expected and restored.state() == running.state()
        counts["tangent"] += exponentials[0]
        exponentials[0] = 0
        largest = max(largest, abs(_cosine(untangent, k, 1)[0].T_ref - expected.T_ref))
        counts["none"] += exponentials[0]
    assert largest <= 1e-12 and counts["tangent"] < counts["none"], (largest, counts)


def test_load_beyond_the_validity_limit_warns_once_per_excursion(params):
    assert params.load_max == pytest.approx(
        params.stress_max * 1e6 * math.pi * params.diameter ** 2 / 4 / 9.80665, rel=1e-12)
    plant = PlantStepper(params, load=0.05)
    compensator = FeedforwardStepper(params)
    above, below = 1.01 * params.load_max, 0.99 * params.load_max
    warnings = []
    for load in (below, above, above, below, above):
        plant.step(1.0, load, STEP)
        compensator.step(42.0, load, STEP)
        warnings.append((plant.warning, compensator.warning))
    assert [w[0] is not None for w in warnings] == [False, True, False, False, True]
    assert [w[1] is not None for w in warnings] == [False, True, False, False, True]
    assert "load = " in warnings[1][0] and "validity.stress_max = 300 MPa" in warnings[1][1]


def test_a_load_that_overflows_the_model_is_refused_naming_the_load(params):
    compensator = FeedforwardStepper(params)
    with pytest.raises(ValueError, match=r"load = 1e\+308 kg is beyond the model's range"):
        compensator.step(42.0, 1e308, STEP)
    plant = PlantStepper(params)
    before = plant.state()
    with pytest.raises(ValueError, match=r"load = 1e\+308 kg"):
        plant.step(1.0, 1e308, STEP)
    assert plant.state() == before
