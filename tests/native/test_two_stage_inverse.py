"""The two-stage inverse (runtime/two_stage_root.py): over 20,000 random points per wire it
returns the temperature the forward model was evaluated at, to 1e-12 K; the C runtime returns
the same doubles; the batch engine the same temperatures to rounding (numpy's exp and log
differ from the C library's in the last bit).

The points: loads 0 ... 0.4 kg, both directions, temperatures from 150 K below the lower
hysteresis centre to 150 K above the upper one, so both stages' ranges and both saturated
ends are crossed; a point the clamp moves (within saturation_margin of an end) is no
invertible target and is skipped, and the test asserts that points near saturation
(min(xi_MF, xi_P) < 1e-4 M) were inverted. The wires: the shape the isobaric fit of the
Flexinol files gives (a sharp stage and a broad one of about equal share, centres close),
two stages apart (w2 = 0.13), a broad small second stage (nu2 = 8, w2 = 0.02) and a second
stage steeper than the first (so the search starts from stage 2's closed form). The same
holds when the search starts from a given temperature (a compensator's last): near the
answer, a transition away, beyond both stages; with the tangent line kept there, or one whose
slope is off by up to a factor 5.
"""
import ctypes
import math
import random

import numpy as np
import pytest

from sma_fmu.runtime.constant_load import branch_constants, branch_fractions
from sma_fmu.runtime.constants import KELVIN_OFFSET
from sma_fmu.runtime.sensing import temperature_of_fractions, temperature_with_tangent
from sma_fmu.studies.batch.branches import two_stage_inverse as batch_inverse

import c_feedforward
from c_runtime import load_with_signatures

POINTS = 20_000
WIRES = {
    "Flexinol fit's shape": dict(a_h=77.2, b_h=71.3, a_c=57.1, b_c=72.7, nu_h=431.6,
                                 nu_c=425.6, w2=0.475, a2_h=78.7, b2_h=57.5, a2_c=53.6,
                                 b2_c=75.6, nu2_h=56.2, nu2_c=52.0),
    "stages apart": dict(nu_h=150.0, nu_c=105.0, w2=0.13, a2_h=95.0, b2_h=80.0, a2_c=70.0,
                         b2_c=45.0, nu2_h=45.0, nu2_c=35.0),
    "broad small stage 2": dict(nu_h=150.0, nu_c=105.0, w2=0.02, a2_h=95.0, b2_h=80.0,
                                a2_c=70.0, b2_c=45.0, nu2_h=8.0, nu2_c=8.0),
    "stage 2 steeper": dict(nu_h=60.0, nu_c=55.0, w2=0.6, a2_h=80.0, b2_h=40.0, a2_c=62.0,
                            b2_c=45.0, nu2_h=400.0, nu2_c=380.0),
}

SHIM = c_feedforward.SHIM + r"""
int invert(const void *params, double load, int direction, double xi_mf, double xi_p,
           double *temperature, int *saturated, char *error) {
    SmaMessage m; BranchConstants b; SensedTemperature t; const WireParameters *p = params;
    if (branch_constants(load, direction, p, &b, &m)
        || temperature_of_fractions(xi_mf, xi_p, &b, p->saturation_margin, &t, &m)) {
        copy_error(error, &m); return 1;
    }
    *temperature = t.temperature; *saturated = t.saturated; return 0;
}
int invert_near(const void *params, double load, int direction, double xi_mf, double xi_p,
                double near, double exponent, double slope, double *temperature,
                int *saturated, double *tangent_exponent, double *tangent_slope, char *error) {
    SmaMessage m; BranchConstants b; SensedTemperature t; const WireParameters *p = params;
    TangentLine line = {exponent, slope}, tangent;
    if (branch_constants(load, direction, p, &b, &m)
        || temperature_near(xi_mf, xi_p, &b, p->saturation_margin, near,
                            isnan(slope) ? NULL : &line, &t, &tangent, &m)) {
        copy_error(error, &m); return 1;
    }
    *temperature = t.temperature; *saturated = t.saturated;
    *tangent_exponent = tangent.exponent; *tangent_slope = tangent.slope; return 0;
}
"""
SIGNATURES = {**c_feedforward.SIGNATURES,
              "invert": (ctypes.c_int, [ctypes.c_void_p, ctypes.c_double, ctypes.c_int,
                                        ctypes.c_double, ctypes.c_double, c_feedforward.DP,
                                        c_feedforward.IP, ctypes.c_char_p]),
              "invert_near": (ctypes.c_int, [ctypes.c_void_p, ctypes.c_double, ctypes.c_int,
                                             ctypes.c_double, ctypes.c_double, ctypes.c_double,
                                             ctypes.c_double, ctypes.c_double,
                                             c_feedforward.DP, c_feedforward.IP,
                                             c_feedforward.DP, c_feedforward.DP,
                                             ctypes.c_char_p])}


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    return load_with_signatures(c_feedforward.RUNTIME, tmp_path_factory.mktemp("inverse"),
                                SHIM, SIGNATURES)


def random_points(params, seed):
    """[(load, direction, T [degC], constants, xi_MF, xi_P)] of POINTS random points."""
    rng, points = random.Random(seed), []
    for _ in range(POINTS):
        load, direction = rng.uniform(0.0, 0.4), rng.choice((1, -1))
        constants = branch_constants(load, direction, params)
        centres = (constants.centre, constants.centre2)
        T = rng.uniform(min(centres) - 150.0, max(centres) + 150.0)
        points.append((load, direction, T, constants, *branch_fractions(T, constants)))
    return points


@pytest.mark.parametrize("wire", sorted(WIRES))
def test_the_inverse_returns_the_forward_models_temperature(params, lib, wire):
    p = params.replace(**WIRES[wire])
    assert p.terms.two_stage
    cparams = c_feedforward.CParameters(lib, p)
    temperature, saturated = ctypes.c_double(), ctypes.c_int()
    error = ctypes.create_string_buffer(512)
    worst, inverted, near_saturation = 0.0, 0, 0
    for load, direction, T, constants, xi_mf, xi_p in random_points(p, 47):
        sensed = temperature_of_fractions(xi_mf, xi_p, constants, p.saturation_margin)
        assert lib.invert(cparams.pointer, load, direction, xi_mf, xi_p,
                          ctypes.byref(temperature), ctypes.byref(saturated), error) == 0
        assert (temperature.value, bool(saturated.value)) == tuple(sensed)   # bit for bit
        if sensed.saturated:        # the clamp moved the target: no temperature to compare
            continue
        inverted += 1
        near_saturation += min(xi_mf, xi_p) < 1e-4 * constants.M
        worst = max(worst, abs(sensed.temperature - T))
    assert worst <= 1e-12, (wire, worst)
    # near saturation: a quarter of the points on the three sharper wires; the broad stage
    # 2 of w2 = 0.02 reaches 1e-4 M only far out, about 1 % of its points
    assert inverted > POINTS // 2 and near_saturation > POINTS // 100, (inverted, near_saturation)


# where a compensator's last temperature lies from the answer [K]: a step's change, a
# transition's width, a jump to the other side of both stages; and no start (NaN, None)
NEAR_OFFSETS = (1e-9, 0.03, -0.03, 2.0, -40.0, 300.0, math.nan)


def _line_near(constants, p, near, rng):
    """The tangent a compensator would keep at ``near`` [degC] on ``constants``' branch (its
    last inversion's), that line's slope scaled by 0.2 ... 5 (a state edited within its
    ranges: the search must still converge), or None."""
    kind = rng.choice(("kept", "kept", "skewed", "none"))
    if near is None or kind == "none":
        return None
    line = temperature_with_tangent(*branch_fractions(near, constants), constants,
                                    p.saturation_margin)[1]
    if line is None or kind == "kept":
        return line
    return line[0], line[1] * rng.uniform(0.2, 5.0)


@pytest.mark.parametrize("wire", sorted(WIRES))
def test_a_start_near_the_answer_returns_it_too(params, lib, wire):
    """The search from a given start (the compensator's last T) and its tangent line: the
    forward model's temperature to 1e-12 K, and the C runtime's doubles, the line at the
    answer included."""
    p = params.replace(**WIRES[wire])
    cparams = c_feedforward.CParameters(lib, p)
    temperature, saturated = ctypes.c_double(), ctypes.c_int()
    exponent, slope = ctypes.c_double(), ctypes.c_double()
    error = ctypes.create_string_buffer(512)
    worst, inverted, lines, rng = 0.0, 0, 0, random.Random(49)
    for load, direction, T, constants, xi_mf, xi_p in random_points(p, 49):
        offset = rng.choice(NEAR_OFFSETS)
        near = None if math.isnan(offset) else T + offset * rng.uniform(0.5, 1.0)
        line = _line_near(constants, p, near, rng)
        lines += line is not None
        sensed, tangent = temperature_with_tangent(xi_mf, xi_p, constants, p.saturation_margin,
                                                   near, line)
        assert lib.invert_near(cparams.pointer, load, direction, xi_mf, xi_p,
                               math.nan if near is None else near,
                               *((math.nan, math.nan) if line is None else line),
                               ctypes.byref(temperature), ctypes.byref(saturated),
                               ctypes.byref(exponent), ctypes.byref(slope), error) == 0
        assert (temperature.value, bool(saturated.value)) == tuple(sensed)   # bit for bit
        if tangent is None:
            assert math.isnan(exponent.value) and math.isnan(slope.value)
        else:
            assert (exponent.value, slope.value) == tangent and tangent[1] > 0.0
        if not sensed.saturated:
            inverted += 1
            worst = max(worst, abs(sensed.temperature - T))
    assert worst <= 1e-12, (wire, worst)
    assert inverted > POINTS // 2 and lines > POINTS // 3, (inverted, lines)


def _batch_arrays(points):
    """The batch engine's arguments for unclamped ``points``: fractions, Lambda, stage 1's
    closed form and the stage constants {M1, M2, minus_energy, ...}."""
    def column(read):
        return np.array([read(c, mf, p) for _, _, _, c, mf, p in points])
    xi_mf, xi_p = column(lambda c, mf, p: mf), column(lambda c, mf, p: p)
    exponent = np.log(xi_p / xi_mf)
    energy, inverse = column(lambda c, *_: c.energy_over_kB), column(lambda c, *_: c.inv_centre_K)
    stages = {"M1": column(lambda c, *_: c.M1), "M2": column(lambda c, *_: c.M2),
              "minus_energy": -energy, "minus_energy2": -column(lambda c, *_: c.energy2_over_kB),
              "inverse": inverse, "inverse2": column(lambda c, *_: c.inv_centre2_K)}
    return xi_mf, xi_p, exponent, inverse - exponent / energy, stages


@pytest.mark.parametrize("wire", sorted(WIRES))
def test_the_batch_inverse_equals_the_runtime(params, wire):
    p = params.replace(**WIRES[wire])
    points = [point for point in random_points(p, 48)[:5000]
              if min(point[4], point[5]) >= p.saturation_margin * point[3].M]
    inverse_kelvin, bad = batch_inverse(*_batch_arrays(points))
    assert not bad.any()
    batch = 1.0 / inverse_kelvin - KELVIN_OFFSET
    scalar = np.array([temperature_of_fractions(mf, xi_p, c, p.saturation_margin).temperature
                       for _, _, _, c, mf, xi_p in points])
    truth = np.array([point[2] for point in points])
    assert np.max(np.abs(batch - scalar)) <= 1e-12
    assert np.max(np.abs(batch - truth)) <= 1e-12
    assert math.isfinite(batch.sum()) and len(points) > 2500
