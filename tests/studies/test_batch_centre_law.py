"""The batch engine equals the scalar library path (<= 1e-10, as tests/studies/test_batch.py)
with the Clausius-Clapeyron centres on (hysteresis.cc_share_h, cc_share_c beside the stress
law and a second stage): random sets of every controller in both hysteresis modes, half the
runs with the law and half without in one batch, and nested minor loops. The batch takes its
centres from the scalar branch constants, so it equals the library by construction; this
checks it."""
import pytest

from sma_fmu.cosim.loop import run_library

from test_batch import mixed_set, nested_scenarios
from test_batch_terms import check, with_terms

LAW = dict(w2=0.2, a2_h=95.0, b2_h=80.0, a2_c=70.0, b2_c=45.0, nu2_h=60.0, nu2_c=50.0,
           span_ratio_0=0.2, span_ratio_sat=1.0, span_stress=150.0, cc_share_h=1.0,
           cc_share_c=0.6)
SHARES_OFF = dict(cc_share_h=None, cc_share_c=None)


def with_law(scenario, changes=LAW):
    """The scenario with ``changes`` in its wire and in its compensator's model."""
    return with_terms(scenario, changes)


def _law_changes_the_run(scenario):
    """The law's run differs from the same run with the shares off (R by more than 1e-6)."""
    law, linear = (run_library(s).data for s in (scenario, with_law(scenario, SHARES_OFF)))
    return abs(linear["R"] - law["R"]).max() > 1e-6


@pytest.mark.parametrize("seed", [4, 7])
def test_random_sets_with_the_law_equal_the_library_path(seed):
    scenarios = mixed_set(12, seed, stop_time_s=2.0)
    scenarios = [with_law(s) if i % 2 == 0 else s for i, s in enumerate(scenarios)]
    check(scenarios)      # batch equals library, run by run (tests/studies/test_batch_terms.py)
    assert any(_law_changes_the_run(s) for s in scenarios[::2])   # the law changed them


def test_nested_minor_loops_with_the_law_equal_the_library_path():
    check([with_law(s) for s in nested_scenarios(stop_time_s=4.0, depths=(4,))])
