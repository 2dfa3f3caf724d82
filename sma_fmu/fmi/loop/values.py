"""What a scenario sets in each component of its loop: parameter values and input starts.

Computed here once for every master and system tool. Each component's parameters are,
besides the scenario's wire in the FMUs that model it (:data:`WIRES`, set whole by
:mod:`.wire_values`): the signals as JSON tables (SmaScenarioSignals; a stroke reference as
the R_ref table it maps to, step by step), the compensator's filter, model load, adaptation,
inverse, shaping, power cap (0 W: none) and anticipation (0 s: none), the PI's gains
(:data:`~.gains.GAINS`) and its sensor (with a ``[sensor]``: noise, ADC, seed), the driver's
frequency and peak power (and, with a limit, its modulation and current and voltage limits),
the plant's start temperature and hysteresis mode.
Choices (the hysteresis mode, the inverse, the shaping, the modulation) are the Integer codes of
:mod:`sma_fmu.fmi.python_family.slave_support.choices`.

An input the signals feed starts at the signal's value at t = 0 (:func:`input_starts`): what
a master that sets the inputs itself, without the signals component, starts the FMU with
(the fmpy master); a system tool connects those inputs instead.
"""
from sma_fmu.fmi.loop.gains import GAINS
from sma_fmu.fmi.python_family.slave_support.choices import choice_code
from sma_fmu.runtime.scenario_signals import table_text
from sma_fmu.runtime.signals import is_stroke

__all__ = ["WIRES", "component_settings", "wire_of", "input_starts"]

# component -> the scenario's attribute holding the wire parameters its FMU gets: the
# plant is the wire, the compensator inverts its model of it (the wire's, unless a study
# changes it)
WIRES = {"compensator": "compensator_params", "plant": "params"}


def _gains(controller, component):
    return {gain.name: getattr(controller, gain.name) for gain in GAINS
            if gain.component == component}


def component_settings(scenario, name, reference_text=None):
    """{parameter: value} the scenario sets in component ``name`` beside the wire's parameters.
    ``reference_text``: the signals' ``reference`` text when the caller made it already (the
    C master maps a stroke reference in C, :mod:`sma_fmu.cosim.stroke_table`)."""
    c, drive = scenario.controller, scenario.drive
    if name == "signals":
        return {"reference": reference_text if reference_text is not None
                else table_text(_reference_table(scenario)),
                "load_profile": table_text(scenario.load.as_table())}
    if name == "compensator":
        return {**_gains(c, name), "adapt_to_load": c.adapt_to_load,
                "inverse": choice_code("inverse", c.inverse),
                "shaping": choice_code("shaping", c.shaping),
                "power_cap": 0.0 if c.power_cap_W is None else c.power_cap_W,
                "anticipation": c.anticipation_s}
    if name == "pi":
        sensor = scenario.sensor
        return _gains(c, name) if sensor.ideal else {
            **_gains(c, name), "noise_ohm_rms": sensor.noise_ohm_rms,
            "full_scale_ohm": sensor.full_scale_ohm, "bits": sensor.bits,
            "seed": sensor.seed}
    if name == "driver":
        settings = {"frequency_Hz": drive.frequency_Hz, "peak_W": drive.peak_W} if drive.pwm \
            else {"modulation": choice_code("modulation", "linear")}
        if drive.limited:
            settings.update(I_max_A=drive.I_max_A, V_max_V=drive.V_max_V)
        return settings
    if name == "plant":
        return {"T_start": scenario.T_start,
                "hysteresis_mode": choice_code("hysteresis_mode", scenario.hysteresis_mode)}
    raise KeyError(name)


def _reference_table(scenario):
    """The signals FMU's ``reference``: the scenario's table, or for a stroke reference the
    R_ref it maps to at every step, as a table in ohm (the FMUs hold no stroke map: the
    master maps the stroke, and the table gives those values at the steps exactly)."""
    reference = scenario.reference
    if is_stroke(reference):
        return reference.resistance_table(scenario.step_s, scenario.steps)
    return reference.as_table()


def wire_of(scenario, name):
    """The WireParameters whose values component ``name``'s FMU gets, or None."""
    attribute = WIRES.get(name)
    return None if attribute is None else getattr(scenario, attribute)


def input_starts(scenario, connections):
    """{component: {input: value}} of the inputs the signals feed (``connections``): the
    signal's value at t = 0 (R_ref [ohm], load [kg])."""
    at_start = {"R_ref": lambda: scenario.reference.value(0.0),
                "load": lambda: scenario.load.value(0.0)}
    starts = {}
    for c in connections:
        if c.source == "signals":
            starts.setdefault(c.target, {})[c.input] = at_start[c.output]()
    return starts
