"""The batch engine equals the scalar library path (<= 1e-10, as tests/test_batch.py) with the
Clausius-Clapeyron centres on (hysteresis.cc_share_h, cc_share_c beside the stress law and a
second stage): random sets of every controller in both hysteresis modes, half the runs with
the law and half without in one batch, and nested minor loops. The batch takes its centres
from the scalar branch constants, so it equals the library by construction; this checks it."""
import dataclasses

import pytest

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.studies import run_batch

from test_batch import assert_same_metrics, assert_same_series, mixed_set, nested_scenarios

LAW = dict(w2=0.2, a2_h=95.0, b2_h=80.0, a2_c=70.0, b2_c=45.0, nu2_h=60.0, nu2_c=50.0,
           span_ratio_0=0.2, span_ratio_sat=1.0, span_stress=150.0, cc_share_h=1.0,
           cc_share_c=0.6)
SHARES_OFF = dict(cc_share_h=None, cc_share_c=None)


def with_law(scenario, changes=LAW):
    """The scenario with ``changes`` in its wire and in its compensator's model."""
    def changed(parameter_set):
        return dataclasses.replace(parameter_set, params=parameter_set.params.replace(**changes))
    model = scenario.compensator_parameter_set
    return dataclasses.replace(scenario, parameter_set=changed(scenario.parameter_set),
                               compensator_parameter_set=None if model is None else changed(model))


def check(scenarios):
    """Batch equals library for every run; returns how many law runs differ from the same
    run with the shares off (R by more than 1e-6 ohm)."""
    differ = 0
    for scenario, result in zip(scenarios, run_batch(scenarios, "timeseries")):
        assert result.path == "batch" and result.error is None, (scenario.name, result.error)
        scalar = run_library(scenario).data
        assert_same_series(result.data, scalar, f"{scenario.controller.kind} "
                                                f"{scenario.hysteresis_mode}")
        assert_same_metrics(result.metrics, scenario_metrics(scalar, scenario))
        if scenario.params.terms.cc_share_h:
            linear = run_library(with_law(scenario, SHARES_OFF)).data
            differ += abs(linear["R"] - scalar["R"]).max() > 1e-6
    return differ


@pytest.mark.parametrize("seed", [4, 7])
def test_random_sets_with_the_law_equal_the_library_path(seed):
    scenarios = mixed_set(12, seed, stop_time_s=2.0)
    scenarios = [with_law(s) if i % 2 == 0 else s for i, s in enumerate(scenarios)]
    assert check(scenarios) > 0    # the law changed what was compared


def test_nested_minor_loops_with_the_law_equal_the_library_path():
    check([with_law(s) for s in nested_scenarios(stop_time_s=4.0, depths=(4,))])
