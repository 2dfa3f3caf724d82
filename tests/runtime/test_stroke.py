"""The stroke map (runtime/stroke.py): stroke [m] at a load -> R_ref [ohm] through the model.

Independent references: on a wire without strain terms R and x are both affine in xi_MF, so
R_ref is the straight line through the two ends of the transformation (written out here from
the spec's fractions, not from the map); on the Flexinol fit (two stages, stress law, thermal
expansion) the plant itself, placed at the map's temperature on the branch, gives back the
asked stroke and R_ref.
"""
import math

import pytest

from sma_fmu.files.package_data import shipped_file
from sma_fmu.runtime.constant_load import branch_constants, branch_fractions
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.signals import load_from_table, reference_from_table
from sma_fmu.runtime.stroke import StrokeMap, StrokeReference, start_length, step_table
from sma_fmu.wire.parameter_file import load_parameter_set


@pytest.fixture(scope="module")
def flexinol():
    return load_parameter_set(shipped_file("models", "flexinol_fit.toml")).params


def _plant_on_branch(params, temperature, load, direction):
    """The plant at ``temperature`` on the major branch of ``direction`` (its own outputs)."""
    plant = PlantStepper(params, temperature, "continuous", load)
    if direction < 0:
        state = plant.state()
        constants = branch_constants(load, direction, params)
        state["direction"] = direction
        state["xi_MF"], state["xi_P"] = branch_fractions(temperature, constants)
        plant.restore(state)
    return plant.outputs


def test_without_strain_terms_R_ref_is_the_straight_line_through_the_ends(params):
    load = 0.05
    x0 = start_length(params, None, 0.0032)
    stroke_map = StrokeMap(params, x0)
    constants = branch_constants(load, 1, params)
    total, residual = constants.M, constants.xi_F_min
    # the ends: all transformable lattice in P (hot), all of it in M and F half and half (cold)
    x_hot = params.l_P * total + params.l_F * residual
    r_hot = params.R_P * total + params.R_F * residual
    x_cold = params.l_M * total / 2 + params.l_F * (residual + total / 2)
    r_cold = params.R_M * total / 2 + params.R_F * (residual + total / 2)
    for stroke_mm in (0.0, 3.0, 8.5, 14.0):
        length = x0 - stroke_mm * 1e-3
        expected = r_hot + (r_cold - r_hot) * (length - x_hot) / (x_cold - x_hot)
        for direction in (1, -1):
            target = stroke_map.target(stroke_mm * 1e-3, load, direction)
            assert not target.clamped
            assert target.R_ref == pytest.approx(expected, abs=1e-12)
            assert target.stroke == stroke_mm * 1e-3


@pytest.mark.parametrize("direction", [1, -1])
@pytest.mark.parametrize("load", [0.1, 0.2, 0.3])
def test_flexinol_stroke_comes_back_from_the_plant_at_the_maps_temperature(flexinol, load,
                                                                           direction):
    x0 = start_length(flexinol, None, 0.1)
    stroke_map = StrokeMap(flexinol, x0)
    for stroke_mm in (5.0, 12.0, 18.0, 25.0, 30.0):
        target = stroke_map.target(stroke_mm * 1e-3, load, direction)
        assert not target.clamped
        outputs = _plant_on_branch(flexinol, target.temperature, load, direction)
        assert x0 - outputs.x == pytest.approx(stroke_mm * 1e-3, abs=1e-9)
        assert outputs.R == pytest.approx(target.R_ref, abs=1e-9)


def test_thermal_expansion_makes_the_branches_differ(flexinol):
    """The heating and cooling branches hold the same (R, xi_MF) at temperatures about one
    hysteresis width apart, so with thermal expansion one stroke needs two R_ref."""
    stroke_map = StrokeMap(flexinol, start_length(flexinol, None, 0.1))
    heating, cooling = (stroke_map.target(15e-3, 0.2, d) for d in (1, -1))
    assert heating.temperature - cooling.temperature > 10.0
    assert heating.R_ref != cooling.R_ref


@pytest.mark.parametrize("stroke_mm,end", [(60.0, "hot"), (-20.0, "cold")])
def test_a_stroke_beyond_reach_is_clamped_to_the_end_it_passes(flexinol, stroke_mm, end):
    x0 = start_length(flexinol, None, 0.1)
    stroke_map = StrokeMap(flexinol, x0)
    target = stroke_map.target(stroke_mm * 1e-3, 0.2, 1)
    assert target.clamped
    constants = branch_constants(0.2, 1, flexinol)
    band = (flexinol.R_P + constants.xi_F_min * (flexinol.R_F - flexinol.R_P))
    width = constants.M * (flexinol.R_MF - flexinol.R_P)
    ref = band if end == "hot" else band + width
    assert target.R_ref == pytest.approx(ref, abs=1e-5 * width)
    assert (target.stroke < stroke_mm * 1e-3) == (end == "hot")
    outputs = _plant_on_branch(flexinol, target.temperature, 0.2, 1)
    assert x0 - outputs.x == pytest.approx(target.stroke, abs=1e-9)


@pytest.mark.parametrize("table,t,trend", [
    ({"kind": "cosine", "offset_mm": 15.0, "amplitude_mm": 8.0, "frequency_hz": 0.5}, 0.5, -1),
    ({"kind": "cosine", "offset_mm": 15.0, "amplitude_mm": 8.0, "frequency_hz": 0.5}, 1.5, 1),
    ({"kind": "cosine", "offset_mm": 15.0, "amplitude_mm": 8.0, "frequency_hz": 0.5}, 2.0, 1),
    ({"kind": "cosine", "offset_mm": 15.0, "amplitude_mm": 8.0, "frequency_hz": 0.5}, 1.0, -1),
    ({"kind": "constant", "value_mm": 15.0}, 3.0, 1),
    ({"kind": "step", "initial_mm": 15.0, "final_mm": 10.0, "time_s": 2.0}, 1.0, 1),
    ({"kind": "step", "initial_mm": 15.0, "final_mm": 10.0, "time_s": 2.0}, 2.0, -1),
    ({"kind": "table", "times_s": [0.0, 1.0, 2.0, 3.0], "values_mm": [5.0, 9.0, 9.0, 4.0]}, 1.5, 1),
    ({"kind": "table", "times_s": [0.0, 1.0, 2.0, 3.0], "values_mm": [5.0, 9.0, 9.0, 4.0]}, 2.5, -1),
    ({"kind": "table", "times_s": [0.0, 1.0, 2.0, 3.0], "values_mm": [5.0, 9.0, 9.0, 4.0]}, 9.0, -1),
])
def test_the_trend_is_the_sign_of_the_last_change(table, t, trend):
    signal = reference_from_table({"quantity": "stroke", **table})
    assert signal.trend(t) == trend
    assert signal.unit == "mm" and signal.as_table().items() >= {"quantity": "stroke", **table}.items()


@pytest.mark.parametrize("values,kept", [
    ([7.0], [0]), ([7.0, 7.0], [0, 1]), ([5.0, 5.0, 5.0, 5.0], [0, 3]),
    ([1.0, 1.0, 2.0, 2.0, 2.0, 3.0], [0, 1, 2, 4, 5]),
    ([1.0, math.nan, math.nan, math.nan, 1.0], [0, 1, 2, 3, 4]),   # NaN equals nothing
])
def test_a_step_table_leaves_out_the_knots_inside_runs_of_equal_values(values, kept):
    table = step_table(0.5, values)
    assert table["times_s"] == [0.5 * k for k in kept]
    assert [repr(v) for v in table["values_ohm"]] == [repr(values[k]) for k in kept]


@pytest.mark.parametrize("table", [
    {"kind": "constant", "value_mm": 15.0},
    {"kind": "cosine", "offset_mm": 15.0, "amplitude_mm": 8.0, "frequency_hz": 0.5},
    {"kind": "table", "times_s": [0.0, 1.0, 2.0], "values_mm": [5.0, 9.0, 4.0]},
])
def test_a_runs_strokes_are_its_stroke_at_each_time(flexinol, table):
    """``strokes`` (the metrics' rows at once) gives ``stroke`` at every time, to the bit."""
    signal = reference_from_table({"quantity": "stroke", **table})
    reference = StrokeReference(signal, load_from_table({"times_s": [0.0], "values_kg": [0.1]}),
                                StrokeMap(flexinol, start_length(flexinol, None, 0.1)))
    times = [0.001 * k for k in range(2501)]
    strokes = reference.strokes(times)
    assert strokes == [reference.stroke(t) for t in times]
    assert (len(set(strokes)) == 1) == (table["kind"] == "constant")
