"""A compensator stepped before its reference arrives (R_ref <= 0 ohm: an unconnected input).

fmpy's ``simulate_ssp`` gives every input 0.0 at the first step. SmaFeedforward takes R_ref
<= 0 before its first R_ref > 0 as no reference yet: P_ff = 0 W, T_ref = T_room, saturated,
one warning, no state change (runtime/feedforward.py's docstring).
"""
import math

import pytest

from sma_fmu.fmi.driving.instance import FmuInstance
from sma_fmu.runtime.feedforward import FeedforwardStepper

STEP = 1e-3


@pytest.mark.parametrize("inverse", ["major", "minor-loop"])
def test_unconnected_steps_change_nothing_and_warn_once(params, inverse):
    waited, fresh = FeedforwardStepper(params, inverse=inverse), FeedforwardStepper(params, inverse=inverse)
    before = waited.state()
    warnings = []
    for reference in (0.0, -3.0, -math.inf, 0.0):
        out = waited.step(reference, 0.05, STEP)
        assert (out.P_ff, out.T_ref, out.saturated) == (0.0, params.T_room, True)
        warnings.append(waited.warning)
    assert waited.state() == before
    assert "before any reference" in warnings[0] and warnings[1:] == [None] * 3
    # then it runs as a compensator that never saw them, bit for bit
    for k in range(300):
        reference = 44.0 - 0.01 * k
        assert waited.step(reference, 0.05, STEP) == fresh.step(reference, 0.05, STEP)
    assert waited.state() == fresh.state()


def test_r_ref_at_or_below_zero_after_a_reference_is_still_refused(params):
    ff = FeedforwardStepper(params)
    ff.step(44.0, 0.05, STEP)
    with pytest.raises(ValueError, match=r"R_ref must be > 0, got 0.0"):
        ff.step(0.0, 0.05, STEP)
    unconnected = FeedforwardStepper(params)
    with pytest.raises(ValueError, match="R_ref must be finite"):   # nan is no "<= 0"
        unconnected.step(math.nan, 0.05, STEP)
    with pytest.raises(ValueError, match=r"load must be >= 0"):   # the other inputs still checked
        unconnected.step(0.0, -1.0, STEP)


def test_initial_outputs_without_a_reference(params):
    out = FeedforwardStepper(params).initial_outputs(0.0, 0.0)
    assert (out.P_ff, out.T_ref, out.saturated) == (0.0, params.T_room, True)


def test_fmu_steps_on_after_a_zero_reference_with_one_warning(fmus, params):
    library = FeedforwardStepper(params)
    with FmuInstance(fmus["SmaFeedforward"], "ff", {"load": 0.05}) as fmu:
        for k in range(3):
            fmu.set_real(("R_ref", "load"), (0.0, 0.0))
            fmu.step(k * STEP, STEP)
            assert fmu.get_real(("P_ff", "T_ref")) == [0.0, params.T_room]
            assert fmu.get_boolean(("saturated",)) == [True]
        warned = [m for m in fmu.messages if m[0] == "warning"]
        assert len(warned) == 1 and "before any reference" in warned[0][-1]
        for k in range(3, 100):
            fmu.set_real(("R_ref", "load"), (44.0 - 0.01 * k, 0.05))
            fmu.step(k * STEP, STEP)
            out = library.step(44.0 - 0.01 * k, 0.05, STEP)
        assert fmu.get_real(("P_ff", "T_ref")) == [out.P_ff, out.T_ref]


@pytest.mark.parametrize("table", [{"kind": "constant", "value_ohm": 0.0},
                                   {"kind": "ramp", "start_time_s": 0.0, "end_time_s": 1.0,
                                    "start_ohm": 44.0, "end_ohm": -1.0}])
def test_the_batch_engine_never_sees_r_ref_at_or_below_zero(table):
    """Its references are scenario signals, which stay > 0 ohm: the unconnected start is a
    host's first step only, so BatchFeedforward needs no such case."""
    from sma_fmu.runtime.signals import reference_from_table

    with pytest.raises(ValueError, match=r"the reference must stay > 0 ohm"):
        reference_from_table(table)
