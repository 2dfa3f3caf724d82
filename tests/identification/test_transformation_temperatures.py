"""The tangent construction gets back tangent temperatures known in closed form, and on
ASMADA's raw file reproduces ASMADA's own per-cycle medians.

Closed forms (independent of the construction's code):
- a logistic step e(T) = lo + (hi - lo) / (1 + exp(-r (T - c))) + m (T - c) is steepest at
  T = c, slope (hi - lo) r / 4 + m; that tangent meets the plateau lines lo + m (T - c) and
  hi + m (T - c) at T = c -+ 2 / r exactly;
- a ramp between sharp corners (plateau, straight ramp, plateau) has its tangent temperatures
  at the corners. A logistic stand-in is steeper at its centre than the ramp, so it finds
  them a little inside the ramp: within 2.5 K on a 20 K ramp.
"""
import numpy as np
import pytest

from sma_fmu.identification.isobaric.files import read_isobaric
from sma_fmu.identification.transformation_temperatures import branch_tangents
from sma_fmu.runtime.constants import HEATING
from real_isobaric import real_folder

COOLING = -HEATING
T = np.linspace(30.0, 220.0, 600)           # degC
COLD, HOT, EXPANSION = 0.040, 0.005, 1e-5   # strain levels [1], plateau slope [1/K]


def _logistic(centre, rate):
    return COLD + (HOT - COLD) / (1.0 + np.exp(-rate * (T - centre))) + EXPANSION * (T - centre)


def _ramp(cold_corner, hot_corner):
    share = np.clip((T - cold_corner) / (hot_corner - cold_corner), 0.0, 1.0)
    return COLD + (HOT - COLD) * share + EXPANSION * (T - 100.0)


@pytest.mark.parametrize("direction, centre, rate", [(HEATING, 118.0, 0.25),
                                                     (COOLING, 97.0, 0.15)])
def test_a_logistic_step_gives_its_closed_form_tangent_temperatures(direction, centre, rate):
    found = branch_tangents(T, _logistic(centre, rate), direction)
    cold_side, hot_side = centre - 2.0 / rate, centre + 2.0 / rate
    expected = (cold_side, hot_side) if direction == HEATING else (hot_side, cold_side)
    assert (found["start"], found["finish"]) == pytest.approx(expected, abs=0.2)
    # strain noise at a raw file's resolution moves them by little
    noisy = _logistic(centre, rate) + np.random.default_rng(7).normal(0.0, 3.5e-5, T.size)
    found = branch_tangents(T, noisy, direction)
    assert (found["start"], found["finish"]) == pytest.approx(expected, abs=0.5)


@pytest.mark.parametrize("direction", [HEATING, COOLING])
def test_a_ramp_between_sharp_corners_gives_its_corners(direction):
    cold_corner, hot_corner = (105.0, 125.0) if direction == HEATING else (90.0, 110.0)
    found = branch_tangents(T, _ramp(cold_corner, hot_corner), direction)
    expected = (cold_corner, hot_corner) if direction == HEATING else (hot_corner, cold_corner)
    assert (found["start"], found["finish"]) == pytest.approx(expected, abs=2.5)
    # the tangent temperatures are not the half-strain temperature
    assert abs(found["start"] - found["finish"]) > 15.0


def test_asmada_s_raw_file_gives_asmada_s_medians(params):
    """Per cycle, as ASMADA made them (its README: A_s 113.1, A_f 128.2, M_s 122.9, M_f
    94.1 degC), the medians agree within 2 K."""
    path = real_folder("asmada-raw") / "isobaric_100cycles.csv"
    data = read_isobaric(path, 0.1, params.x0, params.diameter)
    found = {"A_s": [], "A_f": [], "M_s": [], "M_f": []}
    for b in data.branches:
        rows = slice(b.start, b.stop)
        tangents = branch_tangents(data.smoothed[rows], data.strain[rows], b.direction)
        if tangents is not None:
            start, finish = ("A_s", "A_f") if b.direction == HEATING else ("M_s", "M_f")
            found[start].append(tangents["start"])
            found[finish].append(tangents["finish"])
    assert min(len(v) for v in found.values()) >= 95, {k: len(v) for k, v in found.items()}
    asmada = {"A_s": 113.1, "A_f": 128.2, "M_s": 122.9, "M_f": 94.1}
    medians = {k: float(np.median(v)) for k, v in found.items()}
    for key, value in asmada.items():
        assert medians[key] == pytest.approx(value, abs=2.0), medians


def test_a_baseline_of_a_few_samples_bunched_at_the_turn_gives_no_wild_slope():
    """A cooling branch whose martensite side holds only six samples within 0.1 K (a
    temperature that stalls at the turn), strain noise 1e-4: a line through them has a slope
    of order 1e-4 / 0.1 K (5e-4/K here, 50 times the plateau's), which extrapolated to the
    tangent moved M_f 6.5 K (and the residual strain by that slope times the distance).
    Flat instead, M_f is the closed form's centre - 2/rate within 1 K (the plateau's 1e-5/K
    slope over the bunch is below the noise)."""
    centre, rate = 97.0, 0.15          # cold-side cut at T50 - 2.5 |T25 - T75| = 60.4 degC;
    # the ramp stops short of it, the bunch lies beyond
    ramp = np.linspace(220.0, 66.0, 300)
    bunch = np.linspace(60.0, 59.9, 6)
    t = np.concatenate([ramp, bunch])
    clean = COLD + (HOT - COLD) / (1.0 + np.exp(-rate * (t - centre))) + EXPANSION * (t - centre)
    noise = np.random.default_rng(7).normal(0.0, 1e-4, t.size)
    found = branch_tangents(t, clean + noise, COOLING)
    assert found["finish"] == pytest.approx(centre - 2.0 / rate, abs=1.0)
    assert found["cold"][1] == 0.0
