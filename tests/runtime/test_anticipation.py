"""The shaped compensator's anticipation of the reference's lower turn, against the closed
form of a sampled cosine: where it starts, what it aims at, the hold after the turn."""
import math

import numpy as np
import pytest

from sma_fmu.runtime.anticipation import TurnAnticipation
from sma_fmu.runtime.feedforward import FeedforwardStepper

H = 1e-3                 # sample spacing [s]
OFFSET, AMPLITUDE, FREQUENCY = 41.85, 6.05, 0.5   # the paper's reference [ohm], [Hz]
OMEGA = 2 * math.pi * FREQUENCY


def _cosine(t):
    return OFFSET + AMPLITUDE * np.cos(OMEGA * np.asarray(t))


def _aims(lead, times):
    block = TurnAnticipation(lead)
    return np.array([block.step(float(r), H) for r in _cosine(times)])


def test_it_starts_where_the_turn_is_predicted_within_the_lead():
    """Near the minimum at t0 = 1 s the cosine's -R'/R'' is tan(omega tau)/omega, tau = t0 - t:
    anticipation starts at tau* = atan(omega L)/omega (to a sample: the differences are
    centred one sample back)."""
    lead = 0.2
    times = np.arange(0, 1.0 + H / 2, H)
    aims = _aims(lead, times)
    first = times[np.flatnonzero(aims != _cosine(times))[0]]
    tau = math.atan(OMEGA * lead) / OMEGA
    assert abs((1.0 - first) - tau) <= 2 * H


def test_the_aim_is_the_reference_a_lead_ahead_to_the_taylor_remainder():
    """Inside the window the aim is the second-order Taylor value L ahead: within
    A omega^3 L^3 / 6 (the remainder) plus the differences' O(h) error of R(t + L)."""
    lead = 0.15
    times = np.arange(0, 0.999, H)
    aims = _aims(lead, times)
    inside = aims != _cosine(times)
    assert inside.sum() > 50
    remainder = AMPLITUDE * OMEGA ** 3 * lead ** 3 / 6 + AMPLITUDE * OMEGA ** 2 * lead * H
    assert np.max(np.abs(aims[inside] - _cosine(times[inside] + lead))) <= remainder


def test_no_anticipation_at_the_upper_turn_nor_on_ramps():
    times = np.arange(1.0, 2.2, H)                       # the maximum at t = 2 s
    assert np.array_equal(_aims(0.3, times), _cosine(times))
    block = TurnAnticipation(0.3)
    ramp = [50.0 - 0.01 * k for k in range(300)] + [47.0 + 0.01 * k for k in range(300)]
    assert [block.step(r, H) for r in ramp] == ramp      # a kink, no curvature before it


def test_steps_and_jumps_are_not_turns():
    """A step down, and a cosine that jumps down where it turns (a stroke reference mapped
    onto the other branch there), give three samples with -R'/R'' = h/2: no parabola. The
    aims stay inside the samples' range (a parabola through a 0.4-ohm jump aims thousands
    of ohms away) and a step is passed through as it is."""
    block = TurnAnticipation(0.15)
    step = [50.0] * 100 + [45.0] * 100
    assert [block.step(r, H) for r in step] == step
    times = np.arange(0.5, 1.5, H)
    jumped = _cosine(times) - 0.4 * (times > 1.0)         # the turn at t = 1 s, then 0.4 ohm down
    block = TurnAnticipation(0.15)
    aims = np.array([block.step(float(r), H) for r in jumped])
    assert np.any(aims != jumped)                        # the smooth descent is anticipated
    assert jumped.min() <= aims.min() and aims.max() <= jumped.max()


def test_after_the_turn_the_aim_is_held_until_the_reference_catches_up():
    """No step back after the turn: the aims never fall from the start of the window on, so
    the compensator never reads the exit as heating."""
    times = np.arange(0.7, 1.6, H)
    aims = _aims(0.2, times)
    start = np.flatnonzero(aims != _cosine(times))[0]
    assert np.all(np.diff(aims[start + 1:]) >= 0)
    caught = np.flatnonzero((times > 1.0) & (aims == _cosine(times)))[0]
    assert aims[caught - 1] >= _cosine(times[caught - 1])   # held above R_ref until then


def test_the_compensator_takes_it_only_shaped_and_saves_it_in_its_state(params):
    with pytest.raises(ValueError, match="anticipation = 0.2 s needs shaping 'reachable'"):
        FeedforwardStepper(params, anticipation=0.2)
    with pytest.raises(ValueError, match="anticipation"):
        FeedforwardStepper(params, shaping="reachable", anticipation=-0.1)

    def stepper():
        return FeedforwardStepper(params, shaping="reachable", power_cap=8.3, anticipation=0.2)

    first, times = stepper(), np.arange(0, 1.3, H)
    references = _cosine(times)
    for r in references[:900]:
        first.step(float(r), 0.05, H)
    second = stepper()
    second.restore(first.state())
    rest = [(first.step(float(r), 0.05, H), second.step(float(r), 0.05, H))
            for r in references[900:]]
    assert all(a == b for a, b in rest)
    plain = FeedforwardStepper(params, shaping="reachable", power_cap=8.3)
    unanticipated = [plain.step(float(r), 0.05, H).P_ff for r in references]
    anticipated = stepper()
    powers = [anticipated.step(float(r), 0.05, H).P_ff for r in references]
    assert powers[:700] == unanticipated[:700]               # before the window: the same
    assert max(abs(a - b) for a, b in zip(powers, unanticipated)) > 1.0
