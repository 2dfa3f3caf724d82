"""Read and check a scenario file (TOML): what to simulate, with which controller, how long.

Example (``scenarios/load-step-pi+ff-adaptive.toml``)::

    [scenario]
    description = "..."
    stop_time_s = 30.0
    step_s = 0.001
    # model = "../models/reference_wire.toml"   (parameter file, relative to this file)
    # output_interval_s = 0.01  (optional: record every 10th step; metrics use every step)

    [reference]                 # R_ref(t) in ohm; kinds: constant step ramp sine cosine table
    kind = "cosine"
    offset_ohm = 41.85
    amplitude_ohm = 6.05
    frequency_hz = 0.5
    # quantity = "stroke"       # a stroke reference instead (contraction from the start
                                # length): the same kinds, keys in mm (offset_mm ...); the
                                # controller maps it to R_ref through the model at the load

    [load]                      # piecewise constant: values_kg[i] from times_s[i] on
    times_s = [0.0, 10.0, 20.0]
    values_kg = [0.0032, 0.05, 0.15]

    [controller]                # pi | pi+ff-fixed | pi+ff-adaptive
    kind = "pi+ff-adaptive"     # optional, default from the parameter file's [control]:
                                # Kp_W_per_ohm, Ki_W_per_ohm_s, alpha_s, beta_s, model_load_kg
    # inverse = "minor-loop"    # compensator's inverse: "major" (default, the paper's) or
                                # "minor-loop" (the plant's continuous-mode branches)
    # shaping = "reachable"     # "none" (default, the paper's phase-lag filter) or
                                # "reachable" (the demand shaped into what the wire can reach)
    # power_cap_W = 10.0        # with shaping "reachable": the driver's P_max (default none)
    # anticipation_s = 0.2      # with shaping "reachable": aim this far ahead near the
                                # reference's lower turn (default 0: none)
    [plant]
    hysteresis_mode = "switch"  # default "continuous"; optional T_start_degC (default T_room)

    [drive]                     # optional: how the controller's power reaches the wire
    kind = "pwm"                # "power" (default: the demanded power itself) or "pwm"
    frequency_Hz = 50.0         # pwm: switching frequency; the demand sets each period's duty
    peak_W = 1.0                # pwm: power while on (duty = clip(P_demand / peak_W, 0, 1))
    # I_max_A = 0.5             # optional (either kind): current limit, P <= I_max^2 R
    # V_max_V = 24.0            # optional (either kind): voltage limit, P <= V_max^2 / R

    [sensor]                    # optional: the controller reads R through noise and an ADC
    noise_ohm_rms = 0.05        # white noise [ohm RMS] (an approximately normal stream)
    full_scale_ohm = 65.536     # ADC range 0 ... full scale [ohm], with
    bits = 16                   # its resolution: step full_scale_ohm / 2^bits (0: none)
    seed = 1                    # the noise stream, 0 ... 2^31 - 1

    [analysis]                  # optional; defaults derived from the duration (see AnalysisWindow)
    metrics_start_s = 2.0       # metrics over t >= this
    zoom_start_s = 24.0         # enlarged window of the comparison figures
    zoom_end_s = 28.0

Every problem raises :class:`ScenarioError` naming the file, the key and what is wrong.
A run may have at most :data:`MAX_STEPS` steps.
"""
import math
from pathlib import Path

from sma_fmu.cosim.scenario.settings import (CONTROLLERS, AnalysisWindow, ControllerSettings,
                                             DriveSettings, Scenario, ScenarioError,
                                             SensorSettings, default_analysis)
from sma_fmu.fmi.loop.gains import GAINS
from sma_fmu.wire.parameter_file import load_parameter_set
from sma_fmu.runtime.checks import HYSTERESIS_MODES
from sma_fmu.runtime.constant_load import branch_constants
from sma_fmu.runtime.constants import COOLING, HEATING
from sma_fmu.runtime.feedforward import INVERSES
from sma_fmu.runtime.shaping import SHAPINGS
from sma_fmu.runtime.phase_lag import tustin_coefficients
from sma_fmu.runtime.drive_limit import DriveLimit
from sma_fmu.runtime.measurement import ResistanceSensor
from sma_fmu.runtime.pwm import DRIVE_KINDS, PwmDriver
from sma_fmu.runtime.parameters import ParameterError
from sma_fmu.runtime.signals import load_from_table, reference_from_table
from sma_fmu.runtime.stroke import StrokeMap, StrokeReference, start_length
from sma_fmu.files.toml_files import read_toml

__all__ = ["MAX_STEPS", "load_scenario", "read_scenario_document", "scenario_from_document",
           "check_sections"]

MAX_STEPS = 4_000_000  # 66 min at 1 ms; the time series (113 B per step) is held in memory
_SECTIONS = {
    "scenario": {"description", "stop_time_s", "step_s", "model", "group", "output_interval_s"},
    "reference": None,  # checked by signals.reference_from_table
    "load": None,       # checked by signals.load_from_table
    "controller": {"kind", "inverse", "shaping", "power_cap_W", "anticipation_s", *(gain.key for gain in GAINS)},
    "plant": {"hysteresis_mode", "T_start_degC"},
    "analysis": {"metrics_start_s", "zoom_start_s", "zoom_end_s"},
    "drive": {"kind", "frequency_Hz", "peak_W", "I_max_A", "V_max_V"},
    "sensor": set(SensorSettings.__dataclass_fields__),
}
_LIMITS = ("I_max_A", "V_max_V")

def _fail(path, message):
    raise ScenarioError(f"{path}: {message}")


def _number(path, section, table, key, default=None, positive=False):
    if key not in table:
        if default is None:
            _fail(path, f"[{section}] missing key {key}")
        return default
    value = table[key]
    try:
        number = float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) \
            else math.nan
    except OverflowError:
        number = math.nan
    if not math.isfinite(number):
        _fail(path, f"[{section}] {key} must be a finite number, got {value!r}")
    if positive and not number > 0:
        _fail(path, f"[{section}] {key} must be > 0, got {value!r}")
    return number


def _string(path, section, table, key):
    value = table.get(key)
    if value is not None and not isinstance(value, str):
        _fail(path, f"[{section}] {key} must be a string, got {value!r}")
    return value


def _steps(path, stop, step):
    ratio = stop / step
    if not ratio <= MAX_STEPS:
        _fail(path, f"[scenario] stop_time_s / step_s = {stop!r} / {step!r} = {ratio:.4g} steps; "
                    f"a run may have at most {MAX_STEPS} steps (raise step_s or shorten the run)")
    if abs(ratio - round(ratio)) > 1e-9 * ratio:
        _fail(path, f"[scenario] stop_time_s = {stop!r} is not a whole number of steps of {step!r} s")


def _check_loads(path, load, params):
    """Every load of the profile must be inside the wire model's range (dH(f) > 0, ...)."""
    for value in sorted(set(load.values)):
        for direction in (HEATING, COOLING):
            try:
                branch_constants(value, direction, params)
            except (ValueError, OverflowError) as error:
                _fail(path, f"[load] values_kg: {value!r} kg: {error}")


def _analysis(path, table, stop):
    defaults = default_analysis(stop)
    window = AnalysisWindow(*(_number(path, "analysis", table, key, default=getattr(defaults, key))
                              for key in AnalysisWindow._fields))
    if not 0.0 <= window.metrics_start_s < stop:
        _fail(path, f"[analysis] metrics_start_s = {window.metrics_start_s!r} must be in "
                    f"[0, stop_time_s = {stop!r})")
    if not 0.0 <= window.zoom_start_s < window.zoom_end_s <= stop:
        _fail(path, f"[analysis] zoom_start_s = {window.zoom_start_s!r}, zoom_end_s = "
                    f"{window.zoom_end_s!r}: need 0 <= zoom_start_s < zoom_end_s <= {stop!r}")
    return window


def _controller(path, table, params):
    kind = table.get("kind")
    if kind not in CONTROLLERS:
        _fail(path, f"[controller] kind must be one of {', '.join(CONTROLLERS)}, got {kind!r}")
    values = {}
    for gain in GAINS:
        value = _number(path, "controller", table, gain.key, default=getattr(params, gain.default))
        positive = gain.name == "beta"   # the phase-lag filter's lag time, its pole: not 0
        if value < 0 or (positive and value == 0):
            _fail(path, f"[controller] {gain.key} must be {'> 0' if positive else '>= 0'}, got {value!r}")
        values[gain.name] = value
    inverse = _compensator_choice(path, table, kind, "inverse", INVERSES)
    shaping = _compensator_choice(path, table, kind, "shaping", SHAPINGS)
    cap = None
    if "power_cap_W" in table:
        cap = _number(path, "controller", table, "power_cap_W", positive=True)
        if shaping != "reachable":
            _fail(path, f"[controller] power_cap_W = {cap!r} needs shaping = 'reachable', "
                        f"got {shaping!r}")
    lead = 0.0
    if "anticipation_s" in table:
        lead = _number(path, "controller", table, "anticipation_s")
        if lead < 0:
            _fail(path, f"[controller] anticipation_s must be >= 0, got {lead!r}")
        if lead > 0 and shaping != "reachable":
            _fail(path, f"[controller] anticipation_s = {lead!r} needs shaping = 'reachable', "
                        f"got {shaping!r}")
    return ControllerSettings(kind, inverse=inverse, shaping=shaping, power_cap_W=cap,
                              anticipation_s=lead, **values)


def _compensator_choice(path, table, kind, key, names):
    """[controller] ``key``: one of ``names`` (default the first), other than the default
    only with a feedforward controller."""
    value = table.get(key, names[0])
    if value not in names:
        _fail(path, f"[controller] {key} must be one of {', '.join(names)}, got {value!r}")
    if value != names[0] and kind == "pi":
        _fail(path, f"[controller] {key} = {value!r} needs a feedforward controller "
                    f"(kind pi+ff-fixed or pi+ff-adaptive), got kind 'pi'")
    return value


def _check_filter(path, controller, step):
    """The phase-lag filter's Tustin coefficients at this step must be finite numbers."""
    if not controller.feedforward:
        return
    if not all(math.isfinite(c) for c in tustin_coefficients(controller.alpha, controller.beta, step)):
        _fail(path, f"[controller] alpha_s = {controller.alpha!r}, beta_s = {controller.beta!r}: the "
                    f"phase-lag filter's coefficients at step_s = {step!r} s are not finite "
                    "(alpha_s and beta_s must be far below 1e300 s)")


def _drive(path, table):
    kind = table.get("kind", "power")
    if kind not in DRIVE_KINDS:
        _fail(path, f"[drive] kind must be one of {', '.join(DRIVE_KINDS)}, got {kind!r}")
    limits = {key: _number(path, "drive", table, key, positive=True)
              for key in _LIMITS if key in table}
    if kind == "power":
        extra = sorted(set(table) - {"kind", *_LIMITS})
        if extra:
            _fail(path, f"[drive] {', '.join(extra)} only apply to kind = 'pwm'")
        return DriveSettings(**limits)
    drive = DriveSettings("pwm", _number(path, "drive", table, "frequency_Hz", positive=True),
                          _number(path, "drive", table, "peak_W", positive=True), **limits)
    try:
        PwmDriver(drive.frequency_Hz, drive.peak_W, DriveLimit(drive.I_max_A, drive.V_max_V))
    except ValueError as error:
        _fail(path, f"[drive] {error}")
    return drive


def _sensor(path, table):
    """The ``[sensor]`` table: numbers where numbers go, whole numbers for bits and seed,
    checked by the runtime's own :class:`ResistanceSensor` (its messages)."""
    values = {}
    for key, default in SensorSettings().__dict__.items():
        value = table.get(key, default)
        if isinstance(default, int):
            if isinstance(value, bool) or not isinstance(value, int):
                _fail(path, f"[sensor] {key} must be a whole number, got {value!r}")
        else:
            value = _number(path, "sensor", table, key, default=default)
        values[key] = value
    try:
        ResistanceSensor(**values)
    except ValueError as error:
        _fail(path, f"[sensor] {error}")
    return SensorSettings(**values)


def check_sections(path, document, sections, required, error=ScenarioError):
    """Raise ``error`` for a section or key not in ``sections`` (name -> allowed keys, or None
    for any) and for a missing ``required`` section, naming ``path``."""
    for section, table in document.items():
        if section not in sections:
            raise error(f"{path}: unknown section [{section}]; expected {', '.join(sections)}")
        if not isinstance(table, dict):
            raise error(f"{path}: [{section}] must be a table")
        allowed = sections[section]
        if allowed is not None and set(table) - allowed:
            raise error(f"{path}: [{section}] unknown key(s) "
                        f"{', '.join(sorted(set(table) - allowed))}; "
                        f"expected {', '.join(sorted(allowed))}")
    for section in required:
        if section not in document:
            raise error(f"{path}: missing section [{section}]")


def read_scenario_document(path):
    """The parsed TOML document of a scenario file (not yet validated)."""
    return read_toml(Path(path), ScenarioError, "scenario file")


def load_scenario(path):
    """Read and validate a scenario file; returns a :class:`Scenario`."""
    return scenario_from_document(read_scenario_document(path), Path(path))


def scenario_from_document(document, path, parameter_set=None):
    """Validate a parsed scenario ``document``; ``path`` names it in errors and locates ``model``.

    ``parameter_set`` replaces the parameter file the document names (the study API uses
    it for changed wire parameters); the controller's defaults then come from it.
    """
    path = Path(path)
    check_sections(path, document, _SECTIONS, ("scenario", "reference", "load", "controller"))
    head = document["scenario"]
    stop = _number(path, "scenario", head, "stop_time_s", positive=True)
    step = _number(path, "scenario", head, "step_s", positive=True)
    _steps(path, stop, step)
    interval = None
    if "output_interval_s" in head:
        interval = _number(path, "scenario", head, "output_interval_s", positive=True)
        try:
            _interval_steps(interval, step, "output_interval_s")
        except ValueError as error:
            _fail(path, f"[scenario] {error}")
    model = _string(path, "scenario", head, "model")
    if parameter_set is None:
        try:
            parameter_set = load_parameter_set(None if model is None else path.parent / model)
        except ParameterError as error:
            _fail(path, f"[scenario] model = {model!r}: {error}")
    signals = {}
    for section, build in (("reference", reference_from_table), ("load", load_from_table)):
        try:
            signals[section] = build(document[section])
        except (ValueError, OverflowError) as error:
            _fail(path, f"[{section}] {error}")
    _check_loads(path, signals["load"], parameter_set.params)
    plant = document.get("plant", {})
    mode = plant.get("hysteresis_mode", "continuous")
    if mode not in HYSTERESIS_MODES:
        _fail(path, f"[plant] hysteresis_mode must be 'switch' or 'continuous', got {mode!r}")
    t_start = _number(path, "plant", plant, "T_start_degC", default=parameter_set.params.T_room)
    if not -273.15 < t_start <= parameter_set.params.T_max:
        _fail(path, f"[plant] T_start_degC = {t_start!r} must be above -273.15 degC and at most "
                    f"validity.T_max = {parameter_set.params.T_max!r} degC")
    if signals["reference"].quantity == "stroke":
        signals["reference"] = _stroke_reference(path, signals, parameter_set.params, t_start)
    controller = _controller(path, document["controller"], parameter_set.params)
    _check_filter(path, controller, step)
    return Scenario(
        name=path.stem, path=path, description=str(head.get("description", "")),
        stop_time_s=stop, step_s=step, reference=signals["reference"], load=signals["load"],
        controller=controller,
        hysteresis_mode=mode, T_start=t_start, parameter_set=parameter_set,
        analysis_window=_analysis(path, document["analysis"], stop) if "analysis" in document else None,
        group_name=_string(path, "scenario", head, "group"), output_interval_s=interval,
        drive=_drive(path, document["drive"]) if "drive" in document else DriveSettings(),
        sensor=_sensor(path, document["sensor"]) if "sensor" in document else SensorSettings())


def _stroke_reference(path, signals, params, t_start):
    """The R_ref of a ``[reference] quantity = "stroke"``: the stroke [mm] mapped through the
    wire's model at the load (:class:`~sma_fmu.runtime.stroke.StrokeReference`), counted from
    the plant's length at the start."""
    load = signals["load"]
    try:
        stroke_map = StrokeMap(params, start_length(params, t_start, load.value(0.0)))
        reference = StrokeReference(signals["reference"], load, stroke_map)
        reference.bounds()   # every stroke end at every load maps (or the model says why not)
    except (ValueError, ArithmeticError) as error:
        _fail(path, f"[reference] quantity = 'stroke': {error}")
    return reference


def _interval_steps(*arguments):
    """:func:`~sma_fmu.cosim.recording.interval_steps`, imported when a file sets an output
    interval: the recording imports numpy, which naming a scenario need not wait for."""
    from sma_fmu.cosim.recording import interval_steps

    return interval_steps(*arguments)
