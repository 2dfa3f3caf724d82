"""The wire parameter set: its schema (name, section, unit, rule) and the validated values.

The numbers themselves live only in a parameter file (``models/*.toml``); this module
says what a parameter set must contain and derives the constants the models use
(lattice, thermal gain and time constant, the lengths x_T and x_f).
"""
import math
from collections import namedtuple
from dataclasses import dataclass, field

from .constants import BOLTZMANN, STANDARD_GRAVITY
from .minor_loops import DEFAULT_DEPTH
from .lattice import lattice_constants
from .model_terms import ModelTerms, model_terms
from .thermal import thermal_gain, thermal_time_constant

__all__ = ["ParameterError", "ParameterSpec", "PARAMETER_SPECS", "RULES", "WireParameters",
           "DEFAULT_STRESS_MAX", "DATA_RANGE", "range_text", "requirement_text",
           "value_in_range"]


class ParameterError(ValueError):
    """A parameter set or parameter file is malformed; the message names the key and value."""


ParameterSpec = namedtuple("ParameterSpec",
                           ["name", "section", "unit", "rule", "required", "limits"])
ParameterSpec.__doc__ = """One entry of the parameter schema: where it lives, its unit, its rule
and ``limits`` (low, high), the plausible range in its unit (docs/model.md says why)."""

MAX_MEMORY_DEPTH = 100_000
# The plausible ranges (low, high) [unit]: wide enough for every Ti-Ni, NiTiHf or NiTiCo wire
# and rod and for what the fits reach, narrow enough to refuse a unit slip (a length in mm, a
# resistance in mohm, 1e30). The rule says whether an end is open: positive (low, high],
# nonnegative [low, high], fraction [0, 1), margin (0, 0.5), finite, depth and share
# [low, high].
LENGTH = (0.0, 10.0)               # m: from a few mm (a test coupon) to 10 m of wire
DIAMETER = (0.0, 0.01)             # m: drawn wire 0.025-0.5 mm, rods up to 10 mm
MASS = (0.0, 10.0)                 # kg: 10 m of a 10 mm rod is 5 kg
RESISTANCE = (0.0, 1e5)            # ohm: 10 m of 25 um wire (1.4 kohm/m) is 14 kohm
TEMPERATURE = (-273.15, 1000.0)    # degC: above 0 K; shape setting is at 400-650 degC
CENTRE_SLOPE = (-1e5, 1e5)         # degC/kg: 0.5 K/MPa on a 10 um wire is 6e4 K/kg
LOAD = (0.0, 1e5)                  # kg: 2000 MPa on a 10 mm rod is 1.6e4 kg
STRESS = (0.0, 2000.0)             # MPa: Ti-Ni breaks at 1000-1900 MPa
STRESS_SCALE = (0.0, 1e4)          # MPa: a stress law's scale (the fit reaches 5000)
CELL_ENERGY = (0.0, 1e-17)         # J: 60 eV per cell, 3000 x Ti-Ni's latent heat per cell
CELL_ENERGY_SIGNED = (-1e-17, 1e-17)  # J
DOMAIN_SIZE = (0.0, 1e9)           # cells per domain: far past a step of a millikelvin
EXPANSION = (-0.01, 0.01)          # 1/K: 1000 x a metal's (the fit reaches +-2e-3)
SPAN_RATIO = (0.0, 100.0)          # 1: the stress law's scale of the strain span
SURFACE = (0.0, 1.0)               # m2: 10 m of a 10 mm rod is 0.31 m2
HEAT_CAPACITY = (0.0, 1e4)         # J/(kg.K): Ti-Ni 450-900 (water 4186)
HEAT_TRANSFER = (0.0, 1e5)         # W/(m2.K): still air 5 to boiling water 1e5
TIME = (0.0, 1e5)                  # s: a 10 mm rod in still air has tau_th of about 2700 s
GAIN = (0.0, 1e6)                  # W/ohm, W/(ohm.s): a milliohm rod needs kW per ohm
FRACTION = (0.0, 1.0)              # 1
MARGIN = (0.0, 0.5)                # 1
SHARE = (0.0, 1.0)                 # 1: a share of a slope, both ends included
DEPTH = (2, MAX_MEMORY_DEPTH)      # 1: reversal points

PARAMETER_SPECS = (
    ParameterSpec("x0", "geometry", "m", "positive", True, LENGTH),
    ParameterSpec("x_min", "geometry", "m", "positive", True, LENGTH),
    ParameterSpec("diameter", "geometry", "m", "positive", True, DIAMETER),
    ParameterSpec("theta", "geometry", "1", "fraction", True, FRACTION),
    ParameterSpec("mass", "geometry", "kg", "positive", True, MASS),
    ParameterSpec("R_P", "phases", "ohm", "positive", True, RESISTANCE),
    ParameterSpec("R_M", "phases", "ohm", "positive", True, RESISTANCE),
    ParameterSpec("R_F", "phases", "ohm", "positive", True, RESISTANCE),
    ParameterSpec("l_M", "phases", "m", "positive", True, LENGTH),
    ParameterSpec("l_F", "phases", "m", "positive", True, LENGTH),
    ParameterSpec("a_h", "hysteresis", "degC", "finite", True, TEMPERATURE),
    ParameterSpec("b_h", "hysteresis", "degC/kg", "finite", True, CENTRE_SLOPE),
    ParameterSpec("a_c", "hysteresis", "degC", "finite", True, TEMPERATURE),
    ParameterSpec("b_c", "hysteresis", "degC/kg", "finite", True, CENTRE_SLOPE),
    ParameterSpec("cc_share_h", "hysteresis", "1", "share", False, SHARE),
    ParameterSpec("cc_share_c", "hysteresis", "1", "share", False, SHARE),
    ParameterSpec("memory_depth", "hysteresis", "1", "depth", False, DEPTH),
    ParameterSpec("xi_F_inf", "constant_load", "1", "fraction", True, FRACTION),
    ParameterSpec("f_F", "constant_load", "kg", "positive", True, LOAD),
    ParameterSpec("eps_T", "constant_load", "J", "positive", True, CELL_ENERGY),
    ParameterSpec("nu", "constant_load", "1", "positive", True, DOMAIN_SIZE),
    ParameterSpec("nu_h", "constant_load", "1", "positive", False, DOMAIN_SIZE),
    ParameterSpec("nu_c", "constant_load", "1", "positive", False, DOMAIN_SIZE),
    ParameterSpec("w2", "second_stage", "1", "fraction", False, FRACTION),
    ParameterSpec("a2_h", "second_stage", "degC", "finite", False, TEMPERATURE),
    ParameterSpec("b2_h", "second_stage", "degC/kg", "finite", False, CENTRE_SLOPE),
    ParameterSpec("a2_c", "second_stage", "degC", "finite", False, TEMPERATURE),
    ParameterSpec("b2_c", "second_stage", "degC/kg", "finite", False, CENTRE_SLOPE),
    ParameterSpec("nu2_h", "second_stage", "1", "positive", False, DOMAIN_SIZE),
    ParameterSpec("nu2_c", "second_stage", "1", "positive", False, DOMAIN_SIZE),
    ParameterSpec("alpha_P", "strain", "1/K", "finite", False, EXPANSION),
    ParameterSpec("alpha_MF", "strain", "1/K", "finite", False, EXPANSION),
    ParameterSpec("T_alpha", "strain", "degC", "finite", False, TEMPERATURE),
    ParameterSpec("span_ratio_0", "strain", "1", "positive", False, SPAN_RATIO),
    ParameterSpec("span_ratio_sat", "strain", "1", "positive", False, SPAN_RATIO),
    ParameterSpec("span_stress", "strain", "MPa", "positive", False, STRESS_SCALE),
    ParameterSpec("eps_f", "constant_temperature", "J", "finite", True, CELL_ENERGY_SIGNED),
    ParameterSpec("nu_f", "constant_temperature", "1", "positive", True, DOMAIN_SIZE),
    ParameterSpec("A_s", "thermal", "m2", "positive", True, SURFACE),
    ParameterSpec("c_p", "thermal", "J/(kg.K)", "positive", True, HEAT_CAPACITY),
    ParameterSpec("h_c", "thermal", "W/(m2.K)", "positive", True, HEAT_TRANSFER),
    ParameterSpec("T_room", "thermal", "degC", "finite", True, TEMPERATURE),
    ParameterSpec("saturation_margin", "sensing", "1", "margin", True, MARGIN),
    ParameterSpec("model_load", "control", "kg", "nonnegative", True, LOAD),
    ParameterSpec("alpha", "control", "s", "nonnegative", False, TIME),
    ParameterSpec("beta", "control", "s", "positive", True, TIME),
    ParameterSpec("Kp", "control", "W/ohm", "nonnegative", True, GAIN),
    ParameterSpec("Ki", "control", "W/(ohm.s)", "nonnegative", True, GAIN),
    ParameterSpec("T_max", "validity", "degC", "finite", True, TEMPERATURE),
    ParameterSpec("stress_max", "validity", "MPa", "positive", False, STRESS),
    ParameterSpec("T_data_min", "validity", "degC", "finite", False, TEMPERATURE),
    ParameterSpec("T_data_max", "validity", "degC", "finite", False, TEMPERATURE),
    ParameterSpec("stress_data_min", "validity", "MPa", "nonnegative", False, STRESS),
    ParameterSpec("stress_data_max", "validity", "MPa", "nonnegative", False, STRESS),
)
# The data range (T_data_*, stress_data_*: optional, written by the fits) is where the
# parameters were identified; a stepper warns once when a run leaves it (runtime/validity.py).
DATA_RANGE = ("T_data_min", "T_data_max", "stress_data_min", "stress_data_max")

SPEC_BY_NAME = {spec.name: spec for spec in PARAMETER_SPECS}

# rule -> (low end open, high end open) of its range
RULES = {"positive": (True, False), "nonnegative": (False, False), "fraction": (False, True),
         "finite": (False, False), "margin": (True, True), "depth": (False, False),
         "share": (False, False)}
# choice: Ti-Ni actuator wires are rated for 150-200 MPa over many cycles and yield or lose
# their memory a little above 300 MPa; the reference wire's parameters come from loads up
# to 0.25 kg (139 MPa on 0.15 mm). Above 300 MPa the model warns (0.54 kg on 0.15 mm).
DEFAULT_STRESS_MAX = 300.0   # MPa


def range_text(spec):
    """The plausible range of ``spec`` as an interval in its unit, e.g. ``(0, 100000]``."""
    low_open, high_open = RULES[spec.rule]
    low, high = spec.limits
    return f"{'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"


def requirement_text(spec, value):
    """What ``value`` of ``spec`` must be, as the refusal says it (after "must be")."""
    if spec.rule == "depth":
        return f"a whole number in {range_text(spec)}"
    if not math.isfinite(value):
        return f"a finite number in {range_text(spec)}"
    return f"in {range_text(spec)}"


def value_in_range(spec, value):
    """True if the number ``value`` holds ``spec``'s rule and lies in its plausible range."""
    if not math.isfinite(value) or spec.rule == "depth" and value != int(value):
        return False
    low_open, high_open = RULES[spec.rule]
    low, high = spec.limits
    return (low < value if low_open else low <= value) and \
        (value < high if high_open else value <= high)


@dataclass(frozen=True)
class WireParameters:
    """Validated parameters of one SMA wire (units as in :data:`PARAMETER_SPECS`).

    Derived constants are attributes too: ``lattice`` (N, x_P, N_l, N_S), ``N`` [1],
    ``line_density`` = mass/x0 [kg/m], ``l_P`` = x_min [m], ``x_T`` = l_P - (l_M + l_F)/2 [m],
    ``x_f`` = l_F - (l_P + l_M)/2 [m], ``R_MF`` = (R_M + R_F)/2 [ohm], ``K_th`` [K/W],
    ``tau_th`` [s], ``phase_lag_alpha`` = alpha, or tau_th when alpha is not given [s].
    ``memory_depth`` [1] is the most reversal points the minor-loop memory keeps (an int;
    optional in a file, default 64). ``load_max`` [kg] = stress_max pi d^2/4 / g is the
    largest load the model is valid for (``stress_max`` [MPa], optional, default
    :data:`DEFAULT_STRESS_MAX`): the steppers warn above it. The range the fitted data
    covered, ``T_data_min``/``T_data_max`` [degC] and ``stress_data_min``/``stress_data_max``
    [MPa], is optional (None: no bound); ``load_data_min``/``load_data_max`` [kg] are the
    stress bounds as loads (None when not given), ``data_range`` is True when any bound is
    given: the steppers then warn once when a run leaves the range.

    The optional model terms (``nu_h``, ``nu_c``, ``[second_stage]``, ``[strain]``,
    ``cc_share_h``, ``cc_share_c``) are
    None when not given; ``terms`` (:class:`~.model_terms.ModelTerms`) holds the values in
    use, defaults filled in (nu_h = nu_c = nu, w2 = 0, ...: today's model bit for bit).
    """

    x0: float
    x_min: float
    diameter: float
    theta: float
    mass: float
    R_P: float
    R_M: float
    R_F: float
    l_M: float
    l_F: float
    a_h: float
    b_h: float
    a_c: float
    b_c: float
    xi_F_inf: float
    f_F: float
    eps_T: float
    nu: float
    eps_f: float
    nu_f: float
    A_s: float
    c_p: float
    h_c: float
    T_room: float
    saturation_margin: float
    model_load: float
    beta: float
    Kp: float
    Ki: float
    T_max: float
    alpha: float = None
    memory_depth: int = DEFAULT_DEPTH
    stress_max: float = DEFAULT_STRESS_MAX
    nu_h: float = None
    nu_c: float = None
    w2: float = None
    a2_h: float = None
    b2_h: float = None
    a2_c: float = None
    b2_c: float = None
    nu2_h: float = None
    nu2_c: float = None
    alpha_P: float = None
    alpha_MF: float = None
    T_alpha: float = None
    span_ratio_0: float = None
    span_ratio_sat: float = None
    span_stress: float = None
    cc_share_h: float = None
    cc_share_c: float = None
    T_data_min: float = None
    T_data_max: float = None
    stress_data_min: float = None
    stress_data_max: float = None
    source: str = field(default="<parameters>", compare=False, repr=False)

    lattice: tuple = field(init=False, repr=False, compare=False)
    N: float = field(init=False, repr=False, compare=False)
    line_density: float = field(init=False, repr=False, compare=False)
    l_P: float = field(init=False, repr=False, compare=False)
    x_T: float = field(init=False, repr=False, compare=False)
    x_f: float = field(init=False, repr=False, compare=False)
    R_MF: float = field(init=False, repr=False, compare=False)
    K_th: float = field(init=False, repr=False, compare=False)
    tau_th: float = field(init=False, repr=False, compare=False)
    phase_lag_alpha: float = field(init=False, repr=False, compare=False)
    load_max: float = field(init=False, repr=False, compare=False)
    load_data_min: float = field(init=False, repr=False, compare=False)
    load_data_max: float = field(init=False, repr=False, compare=False)
    data_range: bool = field(init=False, repr=False, compare=False)
    terms: ModelTerms = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        for spec in PARAMETER_SPECS:
            value = getattr(self, spec.name)
            if value is None and not spec.required:
                continue
            self._check(spec, value)
        derived = self._derive()
        for name, value in derived.items():
            object.__setattr__(self, name, value)
        self._check_consistency()

    def _fail(self, message):
        raise ParameterError(f"{self.source}: {message}")

    def _check(self, spec, value):
        key = f"{spec.section}.{spec.name}"
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self._fail(f"parameter {key} must be a number [{spec.unit}], got {value!r}")
        if not value_in_range(spec, float(value)):  # the value as given: an Integer stays one
            self._fail(f"parameter {key} = {value!r} must be "
                       f"{requirement_text(spec, float(value))} [{spec.unit}]")
        value = float(value)
        object.__setattr__(self, spec.name, int(value) if spec.rule == "depth" else value)

    def _derived(self, what, unit, keys, compute):
        """``compute()`` -> value(s) that must be finite and > 0, else ParameterError naming ``keys``."""
        try:
            values = compute()
        except (ZeroDivisionError, OverflowError, ValueError) as error:
            values, reason = None, f"cannot be computed ({error.args[-1] if error.args else error})"
        else:
            numbers = values if isinstance(values, tuple) else (values,)
            bad = [v for v in numbers if not (math.isfinite(v) and v > 0.0)]
            reason = f"= {bad[0]!r} {unit} is not a finite number > 0" if bad else None
        if reason:
            inputs = ", ".join(f"{SPEC_BY_NAME[k].section}.{k} = {getattr(self, k)!r}" for k in keys)
            self._fail(f"derived {what} {reason}; it follows from {inputs}")
        return values

    def _derive(self):
        geometry = ("x0", "x_min", "diameter", "theta", "mass")
        line_density = self._derived("line density mass/x0", "kg/m", ("mass", "x0"),
                                     lambda: self.mass / self.x0)
        lattice = self._derived("lattice (N, x_P, N_l, N_S)", "", geometry, lambda: lattice_constants(
            self.x0, self.x_min, self.diameter, self.theta, line_density))
        gain = self._derived("thermal gain K_th = 1/(h_c A_s)", "K/W", ("h_c", "A_s"),
                             lambda: thermal_gain(self.h_c, self.A_s))
        tau_th = self._derived("thermal time constant tau_th = m c_p/(h_c A_s)", "s",
                               ("mass", "c_p", "h_c", "A_s"),
                               lambda: thermal_time_constant(self.mass, self.c_p, self.h_c, self.A_s))
        self._derived("domain energy over k_B, nu eps_T/k_B", "K", ("nu", "eps_T"),
                      lambda: self.nu * self.eps_T / BOLTZMANN)
        return dict(
            lattice=lattice,
            N=lattice.N,
            line_density=line_density,
            l_P=self.x_min,
            x_T=self.x_min - 0.5 * (self.l_M + self.l_F),
            x_f=self.l_F - 0.5 * (self.x_min + self.l_M),
            R_MF=0.5 * (self.R_M + self.R_F),
            K_th=gain,
            tau_th=tau_th,
            phase_lag_alpha=tau_th if self.alpha is None else self.alpha,
            load_max=self._derived(
                "validity load limit stress_max * pi diameter^2 / 4 / g", "kg",
                ("stress_max", "diameter"),
                lambda: self.stress_max * 1e6 * math.pi * self.diameter ** 2 / 4.0 / STANDARD_GRAVITY),
            terms=model_terms(self, self._fail),
            load_data_min=self._load_of_stress(self.stress_data_min),
            load_data_max=self._load_of_stress(self.stress_data_max),
            data_range=any(getattr(self, name) is not None for name in DATA_RANGE),
        )

    def _load_of_stress(self, stress):
        """The load [kg] of ``stress`` [MPa] on this wire (None for None), as load_max."""
        if stress is None:
            return None
        return stress * 1e6 * math.pi * self.diameter ** 2 / 4.0 / STANDARD_GRAVITY

    def _check_consistency(self):
        if not self.R_MF > self.R_P:
            self._fail(
                f"(R_M + R_F)/2 = {self.R_MF!r} ohm must exceed R_P = {self.R_P!r} ohm: "
                "resistance must fall as the wire transforms to P, or it cannot sense temperature")
        if not self.x_f > 0.0:
            self._fail(
                f"x_f = l_F - (x_min + l_M)/2 = {self.x_f!r} m must be > 0: "
                "the F phase must be the longest")
        if not self.T_room > -273.15:
            self._fail(f"parameter thermal.T_room = {self.T_room!r} degC is below absolute zero")
        if not self.T_max > self.T_room:
            self._fail(f"parameter validity.T_max = {self.T_max!r} degC must exceed "
                       f"thermal.T_room = {self.T_room!r} degC")
        for low, high, unit in (("T_data_min", "T_data_max", "degC"),
                                ("stress_data_min", "stress_data_max", "MPa")):
            lowest, highest = getattr(self, low), getattr(self, high)
            if lowest is not None and highest is not None and not lowest <= highest:
                self._fail(f"parameter validity.{low} = {lowest!r} {unit} must be <= "
                           f"validity.{high} = {highest!r} {unit}")

    def values(self):
        """Parameter values by name (only the schema's entries; alpha omitted when not given)."""
        return {spec.name: getattr(self, spec.name) for spec in PARAMETER_SPECS
                if getattr(self, spec.name) is not None}

    def replace(self, **changes):
        """A copy with some parameter values changed (validated again)."""
        values = self.values()
        unknown = sorted(set(changes) - set(SPEC_BY_NAME))
        if unknown:
            raise ParameterError(f"{self.source}: unknown parameter(s) {', '.join(unknown)}")
        values.update(changes)
        return WireParameters(**values, source=self.source)

    @classmethod
    def from_values(cls, values, source="<parameters>"):
        """Build from a name -> value mapping; unknown or missing names raise ParameterError."""
        unknown = sorted(set(values) - set(SPEC_BY_NAME))
        if unknown:
            raise ParameterError(f"{source}: unknown parameter(s) {', '.join(unknown)}")
        missing = [s.name for s in PARAMETER_SPECS if s.required and s.name not in values]
        if missing:
            raise ParameterError(f"{source}: missing parameter(s) {', '.join(missing)}")
        return cls(**values, source=source)

