"""sma-fmu tune --robust and the loop margins every tuning reports.

The margins against the closed form of the sampled loop (the gain margin at the Nyquist
frequency, where L(-1) is real: (1 + a) / (g K_th (1 - a) (Kp - Ki h / 2))) and the phase
margin against a root of |L(e^(j w h))| = 1 found here with scipy; the slope against a
finite difference of the runtime's branch. The robust criterion: the draws spread the
plant's wire, not the compensator's model, give each draw its own noise stream, and the
score is the quantile of the draws' RMSEs, reproduced on the scalar path.
"""
import cmath
import dataclasses
import json
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from cli_failure import fails
from sma_fmu.cli import main
from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import scenario_metrics
from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios
from sma_fmu.runtime.constant_load import constant_load_resistance
from sma_fmu.runtime.thermal import step_decay
from sma_fmu.studies.margins import loop_margins, loop_transfer, stability_margins, steepest_slope
from sma_fmu.studies.robust import SPREAD_PARAMETERS, RobustCriterion, draw_scenarios, robust_value


def _scenario(name):
    return load_scenario(resolve_scenarios([name])[0])


def _loop(Kp, Ki, g, a, b, h, w):
    z = cmath.exp(1j * w * h)
    return (Kp + Ki * h / (z - 1)) * g * b / (z - a)


@pytest.mark.parametrize("Kp, Ki", [(0.3, 1.0), (5.0, 20.0), (1.0, 0.0)])
def test_margins_against_the_closed_form(params, Kp, Ki):
    h, g = 1e-3, 1.3
    a = step_decay(h, params.tau_th)
    b = params.K_th * (1 - a)
    margins = stability_margins(loop_transfer(Kp, Ki, g, params, h), h)
    assert margins["gain_margin"] == pytest.approx((1 + a) / (g * b * (Kp - Ki * h / 2)), rel=1e-6)
    assert margins["phase_crossover_Hz"] == pytest.approx(0.5 / h, rel=1e-9)
    w = brentq(lambda w: abs(_loop(Kp, Ki, g, a, b, h, w)) - 1.0, 1e-3, math.pi / h * 0.999)
    phase = math.degrees(cmath.phase(_loop(Kp, Ki, g, a, b, h, w)))
    assert margins["phase_margin_deg"] == pytest.approx(180.0 + phase, abs=0.01)
    assert margins["gain_crossover_Hz"] == pytest.approx(w / (2 * math.pi), rel=1e-3)


def test_the_operating_point_is_the_steepest_branch_point():
    scenario = _scenario("heavy-pi")
    slope, temperature, load, direction = steepest_slope(scenario)
    params = scenario.params
    by_hand = abs(constant_load_resistance(temperature + 0.01, load, direction, params)
                  - constant_load_resistance(temperature - 0.01, load, direction, params)) / 0.02
    assert slope == pytest.approx(by_hand, rel=1e-3)
    low, high = scenario.reference.bounds()
    assert low <= constant_load_resistance(temperature, load, direction, params) <= high
    margins = loop_margins(scenario)
    assert margins["slope_ohm_per_K"] == slope and margins["gain_margin_dB"] > 20.0


def test_the_draws_spread_the_wire_and_the_noise_not_the_model():
    scenario = _scenario("load-step-bench-pi+ff-adaptive")
    criterion = RobustCriterion(draws=4, spread=0.1, seed=3)
    draws = draw_scenarios(scenario, criterion)
    assert [d.sensor.seed for d in draws] == [1, 2, 3, 4]
    factors = criterion.factors()
    assert np.all((factors >= 0.9) & (factors <= 1.1)) and np.unique(factors).size == factors.size
    for draw, row in zip(draws, factors):
        for name, factor in zip(SPREAD_PARAMETERS, row):
            assert getattr(draw.params, name) == pytest.approx(getattr(scenario.params, name) * factor,
                                                                rel=1e-15)
        assert draw.compensator_params.values() == scenario.params.values()
        assert draw.params.R_P == scenario.params.R_P
    assert np.array_equal(criterion.factors(), RobustCriterion(draws=4, seed=3).factors())
    assert robust_value([3.0, 1.0, 2.0, 10.0, 4.0], 0.5) == 3.0


def test_robust_tuning_reports_its_score_and_the_margins(tmp_path, capsys):
    out = tmp_path / "tune"
    assert main(["tune", "heavy-bench-pi", "--robust", "--draws", "3", "--stop-time", "2.5",
                 "--generations", "2", "--population", "3", "--out", str(out)]) == 0
    assert "robust score" in capsys.readouterr().out
    record = json.loads((out / "report.json").read_text())[0]
    robust = record["robust"]
    assert robust["draws"] == 3 and robust["spread"] == 0.1 and robust["quantile"] == 0.5
    # the score of the tuned gains, recomputed on the scalar path, is the optimiser's
    assert robust["score_tuned_ohm"] == pytest.approx(record["rmse_ohm"]["tuned_batch"], rel=1e-9)
    assert robust["score_tuned_ohm"] <= robust["score_given_ohm"] + 1e-12
    assert robust["score_tuned_ohm"] == float(np.median(robust["rmse_tuned_ohm"]))
    scenario = load_scenario(resolve_scenarios(["heavy-bench-pi"])[0])
    assert record["margins"]["given"] == loop_margins(
        dataclasses.replace(scenario, stop_time_s=2.5))
    assert len(record["noise_seeds"]["rmse_ohm"]) == 5
    text = (out / "heavy-bench-pi" / "controller.toml").read_text()
    assert "# robust: quantile 0.5 of 3 draws" in text and "margins of the linearised loop" in text
    assert "score given" in (out / "report.md").read_text()


@pytest.mark.parametrize("option, value", [("--quantile", "1.5"), ("--spread", "-0.1"),
                                           ("--draws", "0")])
def test_bad_robust_options_are_refused(tmp_path, capsys, option, value):
    fails(capsys, ["tune", "heavy-pi", "--robust", option, value, "--out", str(tmp_path / "t")],
          option, repr(value))
    assert not (tmp_path / "t").exists()


def test_tuning_without_robust_keeps_its_record(tmp_path):
    out = tmp_path / "tune"
    assert main(["tune", "heavy-pi", "--stop-time", "2.5", "--generations", "1",
                 "--population", "2", "--out", str(out)]) == 0
    record = json.loads((out / "report.json").read_text())[0]
    assert "robust" not in record and "noise_seeds" not in record
    scenario = load_scenario(resolve_scenarios(["heavy-pi"])[0])
    short = dataclasses.replace(scenario, stop_time_s=2.5)
    assert record["rmse_ohm"]["given"] == scenario_metrics(run_library(short).data,
                                                           short)["overall"]["rmse_ohm"]


def test_the_shaped_compensator_is_tuned_on_the_library_path(tmp_path):
    """The batch engine does not implement shaping: the candidates run on the scalar path,
    only Kp and Ki are searched (no filter), and the snippet keeps the shaping's keys."""
    out = tmp_path / "tune"
    name = "heavy-bench-pi+ff-adaptive-reachable"
    assert main(["tune", name, "--robust", "--draws", "2", "--stop-time", "1.5",
                 "--generations", "1", "--population", "2", "--out", str(out)]) == 0
    record = json.loads((out / "report.json").read_text())[0]
    assert set(record["tuned"]) == {"Kp", "Ki"}
    assert "library path" in record["optimiser"]["method"]
    robust = record["robust"]
    assert robust["score_tuned_ohm"] == pytest.approx(record["rmse_ohm"]["tuned_batch"], rel=1e-12)
    assert robust["score_tuned_ohm"] <= robust["score_given_ohm"] + 1e-12
    text = (out / name / "controller.toml").read_text()
    assert 'shaping = "reachable"' in text and "power_cap_W = 8.3" in text
    assert "anticipation_s = 0.15" in text
