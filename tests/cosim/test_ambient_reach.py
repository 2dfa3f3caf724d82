"""Passive cooling stops at T_room: once heated through its transformation, a wire returns at
most to R_amb(f), its cooling major branch at T_room. A wire whose cooling transformation
sits at the ambient (here the reference wire in a room at its own cooling centre, as a NiTi
with M_f below the bench's ambient is) cannot be tracked above R_amb; the run's metrics say
how much of the window asks for that, and warn."""
import json

import numpy as np
import pytest

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.metrics import ambient_edges, scenario_metrics
from sma_fmu.cosim.scenario.reading import load_scenario
from sma_fmu.files.package_data import shipped_file

LOAD = 0.05   # kg


def _band(params, load):
    """(R_hot, R_cold) [ohm] from the spec's formulas (section 4), not the runtime's."""
    residual = params.xi_F_inf * (1.0 - np.exp(-load / params.f_F))
    hot = params.R_P + residual * (params.R_F - params.R_P)
    return hot, hot + (1.0 - residual) * (0.5 * (params.R_M + params.R_F) - params.R_P)


@pytest.fixture(scope="module")
def warm_room(tmp_path_factory):
    """(wire file, its parameters' T_room [degC]): the reference wire in a room at its
    cooling centre at LOAD, a_c + b_c f (spec section 4)."""
    folder = tmp_path_factory.mktemp("warm-room")
    text = shipped_file("models", "reference_wire.toml").read_text(encoding="utf-8")
    centre = 52.0 + 60.0 * LOAD   # a_c, b_c of the file, asserted below
    assert 'a_c = { value = 52.0,' in text and 'b_c = { value = 60.0,' in text
    old = 'T_room = { value = 10.0,'
    assert old in text
    path = folder / "warm_room.toml"
    path.write_text(text.replace(old, f"T_room = {{ value = {centre!r},"), encoding="utf-8")
    return path, centre


def _scenario(folder, wire, value):
    """A 3-s run at LOAD holding R_ref at ``value`` [ohm]."""
    path = folder / f"hold-{value:.6f}.toml"
    path.write_text(f"""[scenario]
description = "a held reference on a wire whose room sits at its cooling centre"
model = {json.dumps(str(wire))}
stop_time_s = 3.0
step_s = 0.001

[reference]
kind = "constant"
value_ohm = {float(value)!r}

[load]
times_s = [0.0]
values_kg = [{LOAD}]

[controller]
kind = "pi+ff-adaptive"

[plant]
hysteresis_mode = "continuous"
""", encoding="utf-8")
    return path


def test_the_ambient_end_is_the_band_middle_at_the_cooling_centre(warm_room, tmp_path):
    """At its centre the cooling logistic holds half the transformable lattice in M: R_amb
    is the middle of the band (closed form), and with the room at 10 degC, 42 K below the
    centre, it is the cold end to within 1e-6 ohm."""
    wire, centre = warm_room
    params = load_scenario(_scenario(tmp_path, wire, 40.0)).params
    assert params.T_room == centre
    hot, cold = _band(params, LOAD)
    assert ambient_edges(np.array([LOAD, LOAD]), params) == pytest.approx([(hot + cold) / 2] * 2,
                                                                          abs=1e-9)
    cool_room = load_scenario(shipped_file("scenarios", "load-step-continuous-pi.toml")).params
    assert cool_room.T_room == 10.0
    assert ambient_edges(np.array([LOAD]), cool_room)[0] == pytest.approx(_band(cool_room, LOAD)[1],
                                                                          abs=1e-6)


@pytest.mark.parametrize("level, above", [(0.75, True), (0.25, False)])
def test_a_reference_above_the_ambient_end_is_counted_and_warned(warm_room, tmp_path, level, above):
    """R_ref held three quarters of the way to R_cold (above R_amb, inside the band): every
    sample of the window counts and one warning names R_amb; a quarter of the way: none."""
    wire, _ = warm_room
    hot, cold = _band(load_scenario(_scenario(tmp_path, wire, 40.0)).params, LOAD)
    scenario = load_scenario(_scenario(tmp_path, wire, hot + level * (cold - hot)))
    metrics = scenario_metrics(run_library(scenario).data, scenario)
    assert metrics["unreachable_fraction"] == 0.0
    assert metrics["above_ambient_fraction"] == (1.0 if above else 0.0)
    warned = [w for w in metrics["warnings"] if "passive cooling" in w]
    if above:
        assert warned == [w for w in metrics["warnings"] if w.startswith("R_ref lies above")]
        assert f"returns only to {(hot + cold) / 2:.4g} ohm at {LOAD:g} kg" in warned[0]
        start = metrics["metrics_start_s"]
        assert f"in 100.0 % of the metric window (from t = {start:g} s)" in warned[0]
    else:
        assert warned == []
