"""A run whose plant discards a step mid-run (t = 0.5 s), for the masters' failure paths.

A scenario file cannot ask for it: the reader refuses a load, a gain or a reference the
model cannot take (every value is checked against the wire and the parameters' plausible
ranges), and so do the metrics and the recorder. A host can still give the plant such an
input mid-run. So the tests run a valid scenario named "discard" and, with :func:`discards`,
hand its signals FMU a load profile that steps to 1e308 kg at t = 0.5 s (the one place where
the loop's parameter values are made, ``fmi/loop/system``): the real signals FMU passes it
on, and the real plant discards that step ("load = 1e+308 kg is beyond the model's range").
"""
import dataclasses

from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.runtime.signals import LoadProfile

# a valid scenario: R_ref steps down at 0.5 s under a constant 0.25 kg; {stop} [s]
VALID = """
[scenario]
stop_time_s = {stop}
step_s = 0.001
[reference]
kind = "step"
initial_ohm = 60.0
final_ohm = 1.0
time_s = 0.5
[load]
times_s = [0.0, 0.5]
values_kg = [0.25, 0.25]
[controller]
kind = "pi"
Kp_W_per_ohm = 0.3
"""
DISCARD_AT_S = 0.5
OUT_OF_RANGE_KG = 1e308
MESSAGE = "load = 1e+308 kg is beyond the model's range"


def with_discard(scenario):
    """``scenario`` with its load from 0.5 s on made 1e308 kg, for a master that computes the
    signals itself (the fmpy master: its plant then discards at t = 0.5 s)."""
    load = LoadProfile([0.0, DISCARD_AT_S], [scenario.load.values[0], OUT_OF_RANGE_KG])
    return dataclasses.replace(scenario, load=load)


def discards(monkeypatch):
    """From now on in this test, the signals FMU of a scenario named "discard" steps its load
    to 1e308 kg at t = 0.5 s (its other components, and every other scenario, unchanged)."""
    from sma_fmu.fmi.loop import system
    from sma_fmu.runtime.scenario_signals import table_text

    settings = system.component_settings

    def component_settings(scenario, name, *rest):
        values = settings(scenario, name, *rest)
        if name == "signals" and scenario.name == "discard":
            load = with_discard(scenario).load
            values = {**values, "load_profile": table_text(load.as_table())}
        return values

    monkeypatch.setattr(system, "component_settings", component_settings)


def valid_path(folder, stop=1.0, name="discard"):
    """The valid scenario's file ``folder/name.toml`` for ``stop`` [s]."""
    path = folder / f"{name}.toml"
    path.write_text(VALID.format(stop=stop))
    return path


def discarding(folder, monkeypatch, stop=1.0):
    """The scenario "discard" of ``stop`` [s] in ``folder``, its plant discarding at 0.5 s."""
    discards(monkeypatch)
    return load_scenario(valid_path(folder, stop))
