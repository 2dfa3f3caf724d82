"""The optional model terms (docs/model.md §4a): what is in use when a file omits them, the stress
law of the transformation strain, and the wire length with thermal expansion.

    nu_d                 domain size on heating / cooling (omitted: nu)
    [second_stage]       share w2 of M transforms by a second logistic, centre a2_d + b2_d f,
                         domain size nu2_d (omitted: b2_d = b_d, nu2_d = nu_d); w2 = 0: off
    [strain]             s(sigma) = span_ratio_sat + (span_ratio_0 - span_ratio_sat) e^(-sigma/span_stress)
                         sigma = g f / (pi d^2/4) [MPa]   (Lagoudas' H_cur form)
                         l_P(T)   = l_P (1 + alpha_P (T - T_alpha))
                         l_i(T,f) = [l_P + s (l_i - l_P)] (1 + alpha_MF (T - T_alpha)),  i = M, F
    cc_share_d           [hysteresis] share c_d of the centre's load slope that follows the
                         transformation strain (Clausius-Clapeyron): tau_d = a_d + b_d f_d,
                         f_d = f [1 + c_d (s_0/s_sat - 1) phi(sigma/span_stress)] [kg],
                         phi(x) = (1 - e^-x)/x, phi(0) = 1, so that
                         d tau_d/df = b_d [1 - c_d + c_d s(sigma)/s_sat]; the second
                         stage's a2_d + b2_d f_d too (omitted: 0, linear centres)

Every default reproduces the paper's model bit for bit: the steppers take the old code path
when ``two_stage`` or ``strain`` is False, and a direction whose ``cc_share_d`` is 0 has
the linear centres. :data:`TERM_DEFAULTS` is the one table of the defaults: the C family's
ModelTerms and its defaults are generated from it at build time
(sma_fmu/fmi/packaging/parameter_table.py); the terms' C physics is in
c_family/runtime/constant_load.c.
"""
import math
from collections import namedtuple

from .constants import STANDARD_GRAVITY

__all__ = ["ModelTerms", "TERM_DEFAULTS", "model_terms", "domain_widths", "stress_of_load",
           "stress_ratio", "centre_load", "stressed_lengths", "wire_length", "length_constants",
           "length_of", "DEFAULT_T_ALPHA",
           "DEFAULT_SPAN_STRESS"]

DEFAULT_T_ALPHA = 20.0        # degC: where l_P, l_M, l_F are the given lengths
DEFAULT_SPAN_STRESS = 100.0   # MPa

# (term, its value when the parameter file omits it): a number, None (stays None), the name
# of a term above (its value in use) or of a parameter of WireParameters (its value). Each
# term is an optional parameter of PARAMETER_SPECS; a new one is a row here.
TERM_DEFAULTS = (
    ("nu_h", "nu"), ("nu_c", "nu"), ("w2", 0.0),
    ("a2_h", None), ("b2_h", "b_h"), ("a2_c", None), ("b2_c", "b_c"),
    ("nu2_h", "nu_h"), ("nu2_c", "nu_c"),
    ("alpha_P", 0.0), ("alpha_MF", 0.0), ("T_alpha", DEFAULT_T_ALPHA),
    ("span_ratio_0", 1.0), ("span_ratio_sat", 1.0), ("span_stress", DEFAULT_SPAN_STRESS),
    ("cc_share_h", 0.0), ("cc_share_c", 0.0),
)

ModelTerms = namedtuple("ModelTerms", [name for name, _ in TERM_DEFAULTS] +
                        ["two_stage", "strain", "area"])
ModelTerms.__doc__ = """The optional terms' values in use (defaults filled in).

nu_h, nu_c, nu2_h, nu2_c [1]; w2 [1]; a2_h, a2_c [degC] (None when stage 2 is off and they
are not given); b2_h, b2_c [degC/kg]; alpha_P, alpha_MF [1/K]; T_alpha [degC]; span_ratio_0,
span_ratio_sat [1]; span_stress [MPa]; cc_share_h, cc_share_c [1]: the share of each
direction's centre slope that follows s(sigma) (0: linear centres); two_stage: w2 > 0;
strain: a thermal expansion or a stress law is on; area: the wire's cross-section
pi d^2/4 [m2].
"""


def domain_widths(values):
    """{"nu_h", "nu_c", "nu"} [1] of ``values`` ({name: value}) holding one shared ``nu`` or
    the widths ``nu_h`` and ``nu_c`` of heating and cooling. One nu is both widths (as in a
    parameter file that omits them: :data:`TERM_DEFAULTS`); two widths give nu = their
    geometric mean (nu_h if either is not > 0), so one nu gives itself back."""
    if "nu_h" in values and "nu_c" in values:
        nu_h, nu_c = values["nu_h"], values["nu_c"]
        return {"nu_h": nu_h, "nu_c": nu_c,
                "nu": math.sqrt(nu_h * nu_c) if nu_h > 0 and nu_c > 0 else nu_h}
    return {"nu_h": values["nu"], "nu_c": values["nu"], "nu": values["nu"]}


def _in_use(params):
    """{term: value in use} of :data:`TERM_DEFAULTS` for ``params``."""
    values = {}
    for name, default in TERM_DEFAULTS:
        value = getattr(params, name)
        if value is None and isinstance(default, str):
            value = values[default] if default in values else getattr(params, default)
        values[name] = default if value is None else value
    return values


def model_terms(params, fail):
    """:class:`ModelTerms` of a :class:`~.parameters.WireParameters` whose own values are
    checked; ``fail(message)`` raises the ParameterError (the file is named by it)."""
    values = _in_use(params)
    w2 = values["w2"]
    if w2 > 0.0:
        for key in ("a2_h", "a2_c"):
            if getattr(params, key) is None:
                fail(f"parameter second_stage.{key} is required when second_stage.w2 = {w2!r} > 0")
    if params.a2_h is not None and params.a2_c is not None and not params.a2_h >= params.a2_c:
        fail(f"parameter second_stage.a2_h = {params.a2_h!r} degC must be >= second_stage.a2_c = "
             f"{params.a2_c!r} degC: the heating centre may not lie below the cooling one")
    return ModelTerms(
        **values,
        two_stage=w2 > 0.0,
        strain=values["alpha_P"] != 0.0 or values["alpha_MF"] != 0.0
        or values["span_ratio_0"] != 1.0 or values["span_ratio_sat"] != 1.0,
        area=math.pi * params.diameter * params.diameter / 4.0,
    )


def stress_of_load(load, terms):
    """Tensile stress sigma [MPa] of ``load`` [kg] on the wire's cross-section."""
    return STANDARD_GRAVITY * load / terms.area / 1e6


def stress_ratio(load, terms):
    """s(sigma) [1]: how the phases' length deviations from l_P scale at ``load`` [kg]."""
    sigma = stress_of_load(load, terms)
    return terms.span_ratio_sat + (terms.span_ratio_0 - terms.span_ratio_sat) * math.exp(
        -sigma / terms.span_stress)


def centre_load(load, share, terms):
    """f_d [kg], the load a centre's slope b_d multiplies when ``share`` c_d [1] of it follows
    the transformation strain (Clausius-Clapeyron: d tau/d sigma = eps_tr(sigma)/ds):

        f_d = integral_0^f [1 - c_d + c_d s(sigma(u))/s_sat] du
            = f [1 + c_d (s_0/s_sat - 1) phi(sigma/span_stress)],   phi(x) = (1 - e^-x)/x

    ``load`` f [kg] >= 0; with s_0 = s_sat or c_d = 0, f_d = f."""
    x = stress_of_load(load, terms) / terms.span_stress
    phi = -math.expm1(-x) / x if x > 0.0 else 1.0
    return load * (1.0 + share * ((terms.span_ratio_0 - terms.span_ratio_sat)
                                  / terms.span_ratio_sat) * phi)


def stressed_lengths(load, params):
    """(l_M, l_F) [m] at ``load`` [kg] and T_alpha: l_P + s (l_i - l_P)."""
    s = stress_ratio(load, params.terms)
    return params.l_P + s * (params.l_M - params.l_P), params.l_P + s * (params.l_F - params.l_P)


def wire_length(temperature, xi_p, xi_m, xi_f, length_m, length_f, params):
    """x [m] at ``temperature`` [degC] of the fractions [1], with the stressed lengths
    ``length_m``, ``length_f`` [m] (:func:`stressed_lengths`) and thermal expansion."""
    return length_of(temperature, xi_p, xi_m, xi_f,
                     length_constants(length_m, length_f, params))


def length_constants(length_m, length_f, params):
    """(T_alpha [degC], alpha_MF, alpha_P [1/K], l_P, l_M, l_F [m]): what :func:`length_of`
    needs, the stressed lengths ``length_m``, ``length_f`` [m] of one load included (a
    plant keeps them with its branch instead of looking them up at every step)."""
    terms = params.terms
    return terms.T_alpha, terms.alpha_MF, terms.alpha_P, params.l_P, length_m, length_f


def length_of(temperature, xi_p, xi_m, xi_f, constants):
    """x [m] at ``temperature`` [degC] of the fractions [1] with thermal expansion:
    l_P (1 + alpha_P dT) xi_P + l_M g xi_M + l_F g xi_F, g = 1 + alpha_MF dT, dT = T - T_alpha,
    ``constants`` from :func:`length_constants`."""
    t_alpha, alpha_mf, alpha_p, length_p, length_m, length_f = constants
    offset = temperature - t_alpha
    grow = 1.0 + alpha_mf * offset
    return (length_p * (1.0 + alpha_p * offset) * xi_p
            + length_m * grow * xi_m + length_f * grow * xi_f)
