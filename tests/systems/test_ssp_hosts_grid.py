"""The signals FMU samples on the step grid k h, whatever rounding the host's time carries.

Hosts that add up their time (Ecos, the container's runtime) reach the end of a set-point
hold a rounding error after k h. Before the signals took their time on the grid, R_ref
there had already left the hold (by 1e-14 ohm), the compensator took the direction of the
reference from the sign of that change, switched branch a step early, and R departed by
16.4 ohm from the library loop on setpoints-pwm-pi+ff-adaptive from t = 7.0 s on (measured
with the same comparison as below: container in fmpy and in libcosim, and Ecos).
"""
import dataclasses
import math

import numpy as np
import pytest

from sma_fmu.cosim.loop import COLUMNS
from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios
from sma_fmu.runtime.scenario_signals import GRID_TOLERANCE, SignalSource, grid_time
from sma_fmu.runtime.signals import load_from_table, reference_from_table
from sma_fmu.systems.comparison import compare_hosts

TOLERANCE = 1e-9
HOLD = {"kind": "table", "times_s": [0.0, 7.0, 7.2], "values_ohm": [38.0, 38.0, 42.0]}


def test_a_time_a_rounding_error_past_the_hold_samples_the_hold():
    h = 1e-3
    late = 7.0 + 4 * math.ulp(7.0)  # 7000 h, as a host that adds up its time reaches it
    reference = reference_from_table(HOLD)
    assert reference.value(late) > 38.0  # the ramp has begun, by a rounding error
    source = SignalSource(reference, load_from_table({"times_s": [0.0], "values_kg": [0.05]}))
    source.step(0.0, h)  # h is the grid's step
    assert source.step(late - h, h).R_ref == 38.0
    assert source.time == 7000 * h


@pytest.mark.parametrize("time_s, expected", [
    (7.0 + 1e-12, 7.0),              # within a millionth of a step: the grid point
    (7.0 - 1e-12, 7.0),
    (7.0 + 2e-9, 7.0 + 2e-9),        # two millionths of a step off: the host's time
    (7.0005, 7.0005),                # half way: a variable-step host's time
    (1.0, 1.0),
])
def test_grid_time_takes_the_grid_point_only_within_the_tolerance(time_s, expected):
    assert GRID_TOLERANCE == 1e-6
    assert grid_time(time_s, 0.0, 1e-3) == expected


def test_grid_time_of_steps_beyond_the_floats_integers_is_the_hosts_time():
    assert grid_time(1.0, 0.0, 5e-324) == 1.0  # 1 / 5e-324 steps: inf
    assert grid_time(1e300, 0.0, 1e-300) == 1e300


def test_hosts_that_add_up_their_time_follow_the_library_through_a_set_point_hold(fmus):
    """The set-point scenario to 7.5 s: the first hold ends at 7.0 s."""
    from sma_fmu.cosim.loop import run_library
    from sma_fmu.systems.runs import run_host

    scenario = dataclasses.replace(
        load_scenario(resolve_scenarios(["setpoints-pwm-pi+ff-adaptive"])[0]), stop_time_s=7.5)
    fmu_dir = fmus["SmaActuator"].parent
    rows = compare_hosts(scenario, fmu_dir, hosts=("fmpy", "libcosim-container"))
    deviations = {row["run"]: row["deviation"] for row in rows}
    assert deviations["fmpy (container)"] <= TOLERANCE
    assert deviations["libcosim-container (container)"] <= TOLERANCE
    # Ecos: R_ref on the grid, exactly; the PWM driver follows Ecos's own time (1e-11 s
    # off k h), which moves P by peak_W dt / h and, through the wire, T and R by ~1e-9
    ecos = run_host("ecos", scenario, fmu_dir).data
    library = run_library(scenario, "jacobi").data
    assert np.array_equal(ecos["R_ref"], library["R_ref"])
    for name, _ in COLUMNS:
        if name != "saturated":
            assert np.nanmax(np.abs(ecos[name] - library[name])) <= 1e-6, name
    assert np.array_equal(ecos["saturated"], library["saturated"])


def test_the_pwm_driver_takes_a_summed_time_on_the_grid(fmus):
    """Stepped with t + h + h + ... (as Ecos and OMSimulator do), the driver FMU gives the
    runtime driver's wave at k h, to the last bit (off the grid, the edges move by the
    rounding: peak / h per second)."""
    from sma_fmu.fmi.driving.instance import FmuInstance
    from sma_fmu.runtime.pwm import PwmDriver

    h, peak = 1e-3, 8.0
    library = PwmDriver(50.0, peak)
    summed, drifted = 0.0, 0.0
    with FmuInstance(fmus["SmaPwmDriver"], "driver", {"frequency_Hz": 50.0, "peak_W": peak}) as fmu:
        for k in range(3000):
            demand = 4.0 + 3.0 * math.sin(k * 1e-3)
            fmu.set_real(("P_demand",), (demand,))
            fmu.step(summed, h)
            assert fmu.get_real(("P_in",)) == [library.step(demand, k * h, h)], k
            drifted = max(drifted, abs(summed - k * h))
            summed += h
    assert drifted > 1e-13  # the summed time did leave the grid


def test_a_step_a_rounding_error_off_the_first_is_taken_as_the_first(fmus, params):
    """OMSimulator steps from t to t_next = t + h passing t_next - t, a few rounding errors
    off h: the plant integrates with h, as the library loop does (a step further off, such
    as a last short step, is taken as it is)."""
    from sma_fmu.fmi.driving.instance import FmuInstance
    from sma_fmu.runtime.plant import PlantStepper

    h = 1e-3
    library = PlantStepper(params, params.T_room, "continuous", 0.05)
    with FmuInstance(fmus["SmaActuator"], "plant", {"load": 0.05}) as fmu:
        time, uneven = 0.0, 0
        for k in range(2000):
            following = time + h
            uneven += (following - time) != h
            fmu.set_real(("P_in", "load"), (2.5, 0.05))
            fmu.step(time, following - time)
            out = library.step(2.5, 0.05, h)
            time = following
        assert uneven > 100  # the host's steps were not h
        assert fmu.get_real(("R", "T")) == [out.R, out.T]
        fmu.step(time, 0.4 * h)  # a short last step: its own size
        out = library.step(2.5, 0.05, 0.4 * h)
        assert fmu.get_real(("R", "T")) == [out.R, out.T]
