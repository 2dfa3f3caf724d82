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

__all__ = ["ParameterError", "ParameterSpec", "PARAMETER_SPECS", "RULE_TEXT", "WireParameters",
           "DEFAULT_STRESS_MAX"]


class ParameterError(ValueError):
    """A parameter set or parameter file is malformed; the message names the key and value."""


ParameterSpec = namedtuple("ParameterSpec", ["name", "section", "unit", "rule", "required"])
ParameterSpec.__doc__ = "One entry of the parameter schema: where it lives, its unit, its rule."

# rule: "positive" (> 0), "nonnegative" (>= 0), "fraction" (0 <= v < 1), "finite",
#       "margin" (0 < v < 0.5), "depth" (a whole number in [2, MAX_MEMORY_DEPTH]),
#       "share" (0 <= v <= 1)
PARAMETER_SPECS = (
    ParameterSpec("x0", "geometry", "m", "positive", True),
    ParameterSpec("x_min", "geometry", "m", "positive", True),
    ParameterSpec("diameter", "geometry", "m", "positive", True),
    ParameterSpec("theta", "geometry", "1", "fraction", True),
    ParameterSpec("mass", "geometry", "kg", "positive", True),
    ParameterSpec("R_P", "phases", "ohm", "positive", True),
    ParameterSpec("R_M", "phases", "ohm", "positive", True),
    ParameterSpec("R_F", "phases", "ohm", "positive", True),
    ParameterSpec("l_M", "phases", "m", "positive", True),
    ParameterSpec("l_F", "phases", "m", "positive", True),
    ParameterSpec("a_h", "hysteresis", "degC", "finite", True),
    ParameterSpec("b_h", "hysteresis", "degC/kg", "finite", True),
    ParameterSpec("a_c", "hysteresis", "degC", "finite", True),
    ParameterSpec("b_c", "hysteresis", "degC/kg", "finite", True),
    ParameterSpec("cc_share_h", "hysteresis", "1", "share", False),
    ParameterSpec("cc_share_c", "hysteresis", "1", "share", False),
    ParameterSpec("memory_depth", "hysteresis", "1", "depth", False),
    ParameterSpec("xi_F_inf", "constant_load", "1", "fraction", True),
    ParameterSpec("f_F", "constant_load", "kg", "positive", True),
    ParameterSpec("eps_T", "constant_load", "J", "positive", True),
    ParameterSpec("nu", "constant_load", "1", "positive", True),
    ParameterSpec("nu_h", "constant_load", "1", "positive", False),
    ParameterSpec("nu_c", "constant_load", "1", "positive", False),
    ParameterSpec("w2", "second_stage", "1", "fraction", False),
    ParameterSpec("a2_h", "second_stage", "degC", "finite", False),
    ParameterSpec("b2_h", "second_stage", "degC/kg", "finite", False),
    ParameterSpec("a2_c", "second_stage", "degC", "finite", False),
    ParameterSpec("b2_c", "second_stage", "degC/kg", "finite", False),
    ParameterSpec("nu2_h", "second_stage", "1", "positive", False),
    ParameterSpec("nu2_c", "second_stage", "1", "positive", False),
    ParameterSpec("alpha_P", "strain", "1/K", "finite", False),
    ParameterSpec("alpha_MF", "strain", "1/K", "finite", False),
    ParameterSpec("T_alpha", "strain", "degC", "finite", False),
    ParameterSpec("span_ratio_0", "strain", "1", "positive", False),
    ParameterSpec("span_ratio_sat", "strain", "1", "positive", False),
    ParameterSpec("span_stress", "strain", "MPa", "positive", False),
    ParameterSpec("eps_f", "constant_temperature", "J", "finite", True),
    ParameterSpec("nu_f", "constant_temperature", "1", "positive", True),
    ParameterSpec("A_s", "thermal", "m2", "positive", True),
    ParameterSpec("c_p", "thermal", "J/(kg.K)", "positive", True),
    ParameterSpec("h_c", "thermal", "W/(m2.K)", "positive", True),
    ParameterSpec("T_room", "thermal", "degC", "finite", True),
    ParameterSpec("saturation_margin", "sensing", "1", "margin", True),
    ParameterSpec("model_load", "control", "kg", "nonnegative", True),
    ParameterSpec("alpha", "control", "s", "nonnegative", False),
    ParameterSpec("beta", "control", "s", "positive", True),
    ParameterSpec("Kp", "control", "W/ohm", "nonnegative", True),
    ParameterSpec("Ki", "control", "W/(ohm.s)", "nonnegative", True),
    ParameterSpec("T_max", "validity", "degC", "finite", True),
    ParameterSpec("stress_max", "validity", "MPa", "positive", False),
)

SPEC_BY_NAME = {spec.name: spec for spec in PARAMETER_SPECS}

RULE_TEXT = {
    "positive": "must be > 0",
    "nonnegative": "must be >= 0",
    "fraction": "must be in [0, 1)",
    "finite": "must be finite",
    "margin": "must be in (0, 0.5)",
    "depth": "must be a whole number in [2, 100000]",
    "share": "must be in [0, 1]",
}
MAX_MEMORY_DEPTH = 100_000
# choice: Ti-Ni actuator wires are rated for 150-200 MPa over many cycles and yield or lose
# their memory a little above 300 MPa; the reference wire's parameters come from loads up
# to 0.25 kg (139 MPa on 0.15 mm). Above 300 MPa the model warns (0.54 kg on 0.15 mm).
DEFAULT_STRESS_MAX = 300.0   # MPa


def _rule_holds(rule, value):
    if not math.isfinite(value):
        return False
    if rule == "positive":
        return value > 0.0
    if rule == "nonnegative":
        return value >= 0.0
    if rule == "fraction":
        return 0.0 <= value < 1.0
    if rule == "margin":
        return 0.0 < value < 0.5
    if rule == "depth":
        return value == int(value) and 2 <= value <= MAX_MEMORY_DEPTH
    if rule == "share":
        return 0.0 <= value <= 1.0
    return True


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
    :data:`DEFAULT_STRESS_MAX`): the steppers warn above it.

    The optional terms of issue 36 (``nu_h``, ``nu_c``, ``[second_stage]``, ``[strain]``,
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
        if not _rule_holds(spec.rule, float(value)):  # the value as given: an Integer stays one
            self._fail(f"parameter {key} = {value!r} {RULE_TEXT[spec.rule]} [{spec.unit}]")
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
        )

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

