"""Thermal step, phase-lag filter and PI against closed forms and python-control."""
import math

import control
import numpy as np
import pytest

from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.phase_lag import PhaseLagFilter
from sma_fmu.runtime.pi_control import PIController
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.thermal import step_decay, thermal_step

H = 1e-3


def _power_profile(n):
    rng = np.random.default_rng(7)
    return np.abs(0.5 + 0.4 * np.sin(np.arange(n) * 0.01) + 0.1 * rng.standard_normal(n))


def test_thermal_step_equals_analytic_solution(params):
    power, t0 = 0.9, 10.0  # W, degC
    temperature, decay = t0, step_decay(H, params.tau_th)
    for k in range(1, 3001):
        temperature = thermal_step(temperature, power, params.T_room, params.K_th, decay)
        t = k * H
        exact = (params.T_room + params.K_th * power
                 + (t0 - params.T_room - params.K_th * power) * math.exp(-t / params.tau_th))
        assert temperature == pytest.approx(exact, abs=1e-11)


def test_plant_temperature_matches_python_control_zoh(params):
    """The plant's thermal part equals G_th(s) = K/(tau s + 1) sampled with ZOH."""
    n = 2000
    power = _power_profile(n)
    plant = PlantStepper(params, load=0.05)
    temperatures = [plant.outputs.T]
    for u in power[:-1]:
        temperatures.append(plant.step(float(u), 0.05, H).T)
    g_th = control.tf([params.K_th], [params.tau_th, 1.0])
    response = control.forced_response(control.sample_system(g_th, H, "zoh"),
                                       T=np.arange(n) * H, U=power)
    reference = params.T_room + np.asarray(response.outputs)
    np.testing.assert_allclose(temperatures, reference, rtol=0, atol=1e-10)


@pytest.mark.parametrize("alpha,beta", [(1.0426, 0.2), (0.5, 0.05), (0.0, 1.0)])
def test_phase_lag_filter_matches_python_control_tustin(alpha, beta):
    n = 3000
    t = np.arange(n) * H
    signal = 2.0 + np.sin(2 * np.pi * 0.5 * t) + 0.3 * np.sign(np.sin(2 * np.pi * 1.3 * t))
    lag = PhaseLagFilter(alpha, beta)
    ours = np.array([lag.step(float(v), H) for v in signal])
    discrete = control.sample_system(control.tf([alpha, 1.0], [beta, 1.0]), H, "tustin")
    # the filter starts in steady state at v_0: by linearity, v_0 (DC gain 1) + response to v - v_0
    reference = signal[0] + np.asarray(control.forced_response(discrete, T=t, U=signal - signal[0]).outputs)
    np.testing.assert_allclose(ours, reference, rtol=0, atol=1e-12)


def test_pi_matches_python_control_forward_euler():
    n, kp, ki = 3000, 0.3, 1.0
    rng = np.random.default_rng(3)
    errors = np.cumsum(rng.standard_normal(n)) * 0.05
    pi = PIController(kp, ki)
    feedforward = 1e3  # W: large enough that the clamp never acts
    ours = np.array([pi.step(float(e), feedforward, H)[0] for e in errors]) - feedforward
    discrete = control.sample_system(control.tf([kp, ki], [1.0, 0.0]), H, "zoh")
    reference = np.asarray(control.forced_response(discrete, T=np.arange(n) * H, U=errors).outputs)
    np.testing.assert_allclose(ours, reference, rtol=0, atol=1e-12)


def test_pi_clamps_at_zero_and_holds_integrator_when_winding_down():
    pi = PIController(0.3, 1.0)
    power, feedback = pi.step(-2.0, 0.1, H)            # u_raw < 0 with e <= 0: clamped, I holds
    assert power == 0.0 and feedback == pytest.approx(-0.6)
    assert pi.integral == 0.0
    power, _ = pi.step(1.0, -5.0, H)                   # clamped but e > 0: I integrates
    assert power == 0.0 and pi.integral == pytest.approx(H)
    power, _ = pi.step(-1.0, 5.0, H)                   # not clamped: I integrates negative e
    assert power > 0.0 and pi.integral == pytest.approx(0.0, abs=1e-18)


def test_feedforward_reference_direction_and_steady_start(params):
    ff = FeedforwardStepper(params, adapt_to_load=True)
    first = ff.initial_outputs(45.0, 0.05)
    out0 = ff.step(45.0, 0.05, H)
    assert out0.P_ff == pytest.approx(first.P_ff, abs=1e-12)  # filter starts in steady state
    assert out0.P_ff == pytest.approx((out0.T_ref - params.T_room) / params.K_th, abs=1e-12)
    assert ff.direction == 1                                  # first sample: heating
    ff.step(44.0, 0.05, H)
    assert ff.direction == 1                                  # falling R_ref: heating
    ff.step(44.5, 0.05, H)
    assert ff.direction == -1                                 # rising R_ref: cooling
    ff.step(44.5, 0.05, H)
    assert ff.direction == -1                                 # equal keeps the last


def test_feedforward_fixed_ignores_measured_load(params):
    fixed = FeedforwardStepper(params, adapt_to_load=False)
    adaptive = FeedforwardStepper(params, adapt_to_load=True)
    at_model_load = adaptive.step(42.0, params.model_load, H)
    assert fixed.step(42.0, 0.25, H) == at_model_load
    heavy = FeedforwardStepper(params, adapt_to_load=True).step(42.0, 0.25, H)
    assert heavy.T_ref > at_model_load.T_ref + 5.0  # transformation shifted up by the load


def test_feedforward_flags_saturated_reference(params):
    ff = FeedforwardStepper(params)
    assert ff.step(60.0, 0.05, H).saturated
    assert not ff.step(42.0, 0.05, H).saturated
