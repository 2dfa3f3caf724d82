"""The compensator never demands a temperature above validity.T_max (issue 29's fuzz finding:
T_ref = 9,859 degC at 100 kg with fmi2OK). Beyond it T_ref is bounded to T_max, P_ff is the
steady-state power of T_max, saturated is True, and each excursion warns once
(runtime/feedforward.py's choice)."""
import dataclasses

import pytest

from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.sensing import sense_temperature

STEP = 1e-3


@pytest.mark.parametrize("inverse", ["major", "minor-loop"])
def test_a_demand_beyond_validity_is_bounded_and_warned_once_per_excursion(params, inverse):
    stepper = FeedforwardStepper(params, inverse=inverse, adapt_to_load=True)
    reference = 0.5 * (params.R_P + params.R_MF)
    unbounded = sense_temperature(reference, 100.0, "heating", params).temperature
    assert unbounded > params.T_max  # the inverse alone would demand this
    warnings, outputs = [], []
    for load in [0.05] * 5 + [100.0] * 20 + [0.05] * 5 + [100.0] * 5:
        outputs.append(stepper.step(reference, load, STEP))
        warnings.append(stepper.warning)
    bounded = outputs[5:25] + outputs[30:]
    assert all(o.T_ref == params.T_max and o.saturated for o in bounded)
    # P_ff is the (lead-filtered) power of T_max, far below what a bound at the highest T_max
    # the schema allows (1000 degC) lets the inverse ask
    free = FeedforwardStepper(dataclasses.replace(params, T_max=1000.0), inverse=inverse,
                              adapt_to_load=True)
    asked = [free.step(reference, load, STEP).P_ff for load in [0.05] * 5 + [100.0] * 20]
    steady = (params.T_max - params.T_room) / params.K_th
    assert outputs[24].P_ff < 0.5 * asked[24] and outputs[24].P_ff > steady
    assert outputs[4].T_ref < params.T_max and outputs[29].T_ref < params.T_max
    assert "bounded to T_max" in warnings[5] and "bounded to T_max" in warnings[30]
    assert [w for k, w in enumerate(warnings) if w and "bounded" in w and k not in (5, 30)] == []


def test_within_validity_nothing_changes(params):
    """Below T_max the outputs are the inverse's (the paper's loads never reach the bound)."""
    stepper = FeedforwardStepper(params, adapt_to_load=True)
    for k in range(200):
        reference = 40.0 + 0.02 * k
        out = stepper.step(reference, 0.15, STEP)
        sensed = sense_temperature(reference, 0.15, "heating" if k == 0 else "cooling", params)
        assert out.T_ref == sensed.temperature and out.saturated == sensed.saturated
