"""Qualitative behaviour the paper reports (sections 2-3, Figs. 4 and 6)."""
import pytest

from sma_fmu.runtime.constant_load import branch_constants, constant_load_resistance
from sma_fmu.runtime.constant_temperature import ConstantTemperatureModel
from sma_fmu.runtime.constants import COOLING, HEATING
from sma_fmu.runtime.sensing import temperature_of_fractions

LOADS = [0.0032, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3]


def _temperature_at(fraction_of_m, load, direction, params):
    """Temperature [degC] where xi_MF = fraction_of_m * M on a major branch."""
    constants = branch_constants(load, direction, params)
    xi_mf = fraction_of_m * constants.M
    return temperature_of_fractions(xi_mf, constants.M - xi_mf, constants,
                                    params.saturation_margin).temperature


def _strictly_increasing(values):
    return all(b > a for a, b in zip(values, values[1:]))


@pytest.mark.parametrize("direction", [HEATING, COOLING])
@pytest.mark.parametrize("fraction_of_m", [0.9, 0.5, 0.1])
def test_transformation_temperatures_rise_with_load(params, direction, fraction_of_m):
    temperatures = [_temperature_at(fraction_of_m, f, direction, params) for f in LOADS]
    assert _strictly_increasing(temperatures)


def test_hysteresis_width_grows_with_load(params):
    widths = [_temperature_at(0.5, f, HEATING, params) - _temperature_at(0.5, f, COOLING, params)
              for f in LOADS]
    assert widths[0] == pytest.approx(16.0 + 40.0 * 0.0032, abs=1e-9)
    assert _strictly_increasing(widths)


@pytest.mark.parametrize("direction", [HEATING, COOLING])
def test_high_temperature_resistance_rises_with_load(params, direction):
    hot = [constant_load_resistance(110.0, f, direction, params) for f in LOADS]
    assert _strictly_increasing(hot)
    assert hot[-1] - hot[0] > 1.0  # residual F under 0.3 kg is worth more than 1 ohm


def test_resistance_falls_through_the_transformation(params):
    for direction in (HEATING, COOLING):
        curve = [constant_load_resistance(t, 0.05, direction, params) for t in range(10, 111, 5)]
        assert all(b <= a for a, b in zip(curve, curve[1:]))
        assert curve[0] - curve[-1] > 15.0


def _ramp(start, end, points=200):
    return [start + (end - start) * i / points for i in range(1, points + 1)]


def test_fig6_load_sequence_ratchets(params):
    """0 -> 0.1 -> 0.03 -> 0.2 -> 0.03 -> 0.3 kg at 20 degC: resistance does not return."""
    model = ConstantTemperatureModel(20.0, params)
    legs = [(0.0, 0.1), (0.1, 0.03), (0.03, 0.2), (0.2, 0.03), (0.03, 0.3)]
    start = model.resistance_sequence([0.0])[0]
    runs = [(loads, model.resistance_sequence(loads)) for loads in (_ramp(a, b) for a, b in legs)]
    (up1, r_up1), (down1, r_down1), (up2, r_up2), (down2, r_down2), (up3, r_up3) = runs

    at = lambda loads, values, f: values[min(range(len(loads)), key=lambda i: abs(loads[i] - f))]
    # first loading to 0.1 kg lowers the resistance (M -> F, R_F < R_M)
    assert r_up1[-1] < start - 0.1
    # unloading to 0.03 kg: it does not return ...
    assert abs(r_down1[-1] - r_up1[-1]) < 1e-3
    assert r_down1[-1] < at(up1, r_up1, 0.03) - 0.1
    # ... and reloading does not move it until the previous maximum 0.1 kg is passed
    below_previous_max = [r for f, r in zip(up2, r_up2) if f <= 0.1]
    assert max(below_previous_max) - min(below_previous_max) < 1e-3
    assert r_up2[-1] < r_up1[-1] - 0.2
    # the second unloading holds too, and the last loading moves only past 0.2 kg
    assert abs(r_down2[-1] - r_up2[-1]) < 1e-3
    below_second_max = [r for f, r in zip(up3, r_up3) if f <= 0.2]
    assert max(below_second_max) - min(below_second_max) < 1e-3
    assert r_up3[-1] < r_up2[-1] - 0.1


def test_critical_load_and_width_at_20C(params):
    from sma_fmu.runtime.constant_temperature import loading_fraction
    assert loading_fraction(0.15, 20.0, params) == pytest.approx(0.5, abs=0.01)
    width = 1.0 / 20.0  # spec: width about 0.05 kg -> slope of the logistic about 20 per kg
    rise = loading_fraction(0.15 + width, 20.0, params) - loading_fraction(0.15 - width, 20.0, params)
    assert 0.4 < rise < 0.6
