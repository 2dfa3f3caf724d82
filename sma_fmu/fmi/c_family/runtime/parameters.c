/* The wire parameter set; runtime/parameters.py (see parameters.h). */
#include "fp_contract.h"
#include "parameters.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "constants.h"
#include "thermal.h"

const ParameterSpec PARAMETER_SPECS[PARAM_COUNT] = {
    {"x0", "geometry", "m", RULE_POSITIVE, 1},
    {"x_min", "geometry", "m", RULE_POSITIVE, 1},
    {"diameter", "geometry", "m", RULE_POSITIVE, 1},
    {"theta", "geometry", "1", RULE_FRACTION, 1},
    {"mass", "geometry", "kg", RULE_POSITIVE, 1},
    {"R_P", "phases", "ohm", RULE_POSITIVE, 1},
    {"R_M", "phases", "ohm", RULE_POSITIVE, 1},
    {"R_F", "phases", "ohm", RULE_POSITIVE, 1},
    {"l_M", "phases", "m", RULE_POSITIVE, 1},
    {"l_F", "phases", "m", RULE_POSITIVE, 1},
    {"a_h", "hysteresis", "degC", RULE_FINITE, 1},
    {"b_h", "hysteresis", "degC/kg", RULE_FINITE, 1},
    {"a_c", "hysteresis", "degC", RULE_FINITE, 1},
    {"b_c", "hysteresis", "degC/kg", RULE_FINITE, 1},
    {"memory_depth", "hysteresis", "1", RULE_DEPTH, 0},
    {"xi_F_inf", "constant_load", "1", RULE_FRACTION, 1},
    {"f_F", "constant_load", "kg", RULE_POSITIVE, 1},
    {"eps_T", "constant_load", "J", RULE_POSITIVE, 1},
    {"nu", "constant_load", "1", RULE_POSITIVE, 1},
    {"nu_h", "constant_load", "1", RULE_POSITIVE, 0},
    {"nu_c", "constant_load", "1", RULE_POSITIVE, 0},
    {"w2", "second_stage", "1", RULE_FRACTION, 0},
    {"a2_h", "second_stage", "degC", RULE_FINITE, 0},
    {"b2_h", "second_stage", "degC/kg", RULE_FINITE, 0},
    {"a2_c", "second_stage", "degC", RULE_FINITE, 0},
    {"b2_c", "second_stage", "degC/kg", RULE_FINITE, 0},
    {"nu2_h", "second_stage", "1", RULE_POSITIVE, 0},
    {"nu2_c", "second_stage", "1", RULE_POSITIVE, 0},
    {"alpha_P", "strain", "1/K", RULE_FINITE, 0},
    {"alpha_MF", "strain", "1/K", RULE_FINITE, 0},
    {"T_alpha", "strain", "degC", RULE_FINITE, 0},
    {"span_ratio_0", "strain", "1", RULE_POSITIVE, 0},
    {"span_ratio_sat", "strain", "1", RULE_POSITIVE, 0},
    {"span_stress", "strain", "MPa", RULE_POSITIVE, 0},
    {"eps_f", "constant_temperature", "J", RULE_FINITE, 1},
    {"nu_f", "constant_temperature", "1", RULE_POSITIVE, 1},
    {"A_s", "thermal", "m2", RULE_POSITIVE, 1},
    {"c_p", "thermal", "J/(kg.K)", RULE_POSITIVE, 1},
    {"h_c", "thermal", "W/(m2.K)", RULE_POSITIVE, 1},
    {"T_room", "thermal", "degC", RULE_FINITE, 1},
    {"saturation_margin", "sensing", "1", RULE_MARGIN, 1},
    {"model_load", "control", "kg", RULE_NONNEGATIVE, 1},
    {"alpha", "control", "s", RULE_NONNEGATIVE, 0},
    {"beta", "control", "s", RULE_POSITIVE, 1},
    {"Kp", "control", "W/ohm", RULE_NONNEGATIVE, 1},
    {"Ki", "control", "W/(ohm.s)", RULE_NONNEGATIVE, 1},
    {"T_max", "validity", "degC", RULE_FINITE, 1},
    {"stress_max", "validity", "MPa", RULE_POSITIVE, 0},
};

static const char *const RULE_TEXT[] = {
    "must be > 0", "must be >= 0", "must be in [0, 1)", "must be finite",
    "must be in (0, 0.5)", "must be a whole number in [2, 100000]",
};

static int rule_holds(ParameterRule rule, double value)
{
    if (!isfinite(value)) {
        return 0;
    }
    switch (rule) {
    case RULE_POSITIVE: return value > 0.0;
    case RULE_NONNEGATIVE: return value >= 0.0;
    case RULE_FRACTION: return 0.0 <= value && value < 1.0;
    case RULE_MARGIN: return 0.0 < value && value < 0.5;
    case RULE_DEPTH: return value == trunc(value) && 2 <= value && value <= MAX_MEMORY_DEPTH;
    default: return 1;
    }
}

static int is_finite_positive(double value)
{
    return isfinite(value) && value > 0.0;
}

/* The ParameterError of a derived constant: `failure` (an exception's text) or the first of
 * `numbers` that is not finite and > 0; `keys` the parameters it follows from. */
static int derived_failure(const WireParameters *p, const double *values, const char *what,
                           const char *unit, const ParameterIndex *keys, int key_count,
                           const double *numbers, int number_count, const char *failure,
                           SmaMessage *message)
{
    char reason[128], inputs[400];
    size_t used = 0;
    int i;
    if (failure != NULL) {
        snprintf(reason, sizeof reason, "cannot be computed (%s)", failure);
    } else {
        for (i = 0; i < number_count && is_finite_positive(numbers[i]); i++) {
        }
        if (i == number_count) {
            return 0;
        }
        snprintf(reason, sizeof reason, "= %.17g %s is not a finite number > 0", numbers[i], unit);
    }
    inputs[0] = '\0';
    for (i = 0; i < key_count && used < sizeof inputs; i++) {
        int written = snprintf(inputs + used, sizeof inputs - used, "%s%s.%s = %.17g",
                               i ? ", " : "", PARAMETER_SPECS[keys[i]].section,
                               PARAMETER_SPECS[keys[i]].name, values[keys[i]]);
        used += written > 0 ? (size_t)written : 0;
    }
    return sma_message_set(message, "%s: derived %s %s; it follows from %s", p->source, what,
                           reason, inputs);
}

/* The value in use of an optional parameter: `value`, or `fallback` when not given (NaN). */
static double value_or(double value, double fallback)
{
    return isnan(value) ? fallback : value;
}

/* ModelTerms of the checked values v[] (model_terms.py's model_terms, same messages). */
static int model_terms(const WireParameters *p, const double v[], ModelTerms *t,
                       SmaMessage *message)
{
    double a2_h = v[PARAM_a2_h], a2_c = v[PARAM_a2_c];
    t->nu_h = value_or(v[PARAM_nu_h], p->nu);
    t->nu_c = value_or(v[PARAM_nu_c], p->nu);
    t->w2 = value_or(v[PARAM_w2], 0.0);
    if (t->w2 > 0.0) {
        if (isnan(a2_h) || isnan(a2_c)) {
            return sma_message_set(message, "%s: parameter second_stage.%s is required when "
                                   "second_stage.w2 = %.17g > 0", p->source,
                                   isnan(a2_h) ? "a2_h" : "a2_c", t->w2);
        }
    }
    if (!isnan(a2_h) && !isnan(a2_c) && !(a2_h >= a2_c)) {
        return sma_message_set(message, "%s: parameter second_stage.a2_h = %.17g degC must be >= "
                               "second_stage.a2_c = %.17g degC: the heating centre may not lie "
                               "below the cooling one", p->source, a2_h, a2_c);
    }
    t->a2_h = a2_h;
    t->a2_c = a2_c;
    t->b2_h = value_or(v[PARAM_b2_h], p->b_h);
    t->b2_c = value_or(v[PARAM_b2_c], p->b_c);
    t->nu2_h = value_or(v[PARAM_nu2_h], t->nu_h);
    t->nu2_c = value_or(v[PARAM_nu2_c], t->nu_c);
    t->alpha_P = value_or(v[PARAM_alpha_P], 0.0);
    t->alpha_MF = value_or(v[PARAM_alpha_MF], 0.0);
    t->T_alpha = value_or(v[PARAM_T_alpha], DEFAULT_T_ALPHA);
    t->span_ratio_0 = value_or(v[PARAM_span_ratio_0], 1.0);
    t->span_ratio_sat = value_or(v[PARAM_span_ratio_sat], 1.0);
    t->span_stress = value_or(v[PARAM_span_stress], DEFAULT_SPAN_STRESS);
    t->two_stage = t->w2 > 0.0;
    t->strain = t->alpha_P != 0.0 || t->alpha_MF != 0.0 || t->span_ratio_0 != 1.0
                || t->span_ratio_sat != 1.0;
    t->area = SMA_PI * p->diameter * p->diameter / 4.0;
    return 0;
}

/* The parameter values as checked (defaults for optional ones not given), in spec order.
 * `given` NULL: an optional parameter's NaN means "not given"; else given[i] says it, and a
 * NaN that was given is refused by name like any value that breaks its rule. */
static int check_values(WireParameters *p, const double values[], const unsigned char *given,
                        double checked[], SmaMessage *message)
{
    int index;
    for (index = 0; index < PARAM_COUNT; index++) {
        const ParameterSpec *spec = &PARAMETER_SPECS[index];
        double value = values[index];
        if (!spec->required && (given != NULL ? !given[index] : isnan(value))) {
            if (index == PARAM_memory_depth) {
                value = DEFAULT_DEPTH;
            } else if (index == PARAM_stress_max) {
                value = DEFAULT_STRESS_MAX;
            } else {
                checked[index] = NAN;     /* alpha and the terms: None (NaN below) */
                continue;
            }
        }
        if (!rule_holds(spec->rule, value)) {
            return sma_message_set(message, "%s: parameter %s.%s = %.17g %s [%s]", p->source,
                                   spec->section, spec->name, value, RULE_TEXT[spec->rule],
                                   spec->unit);
        }
        checked[index] = value;
    }
    return 0;
}

int wire_parameters_from_values_source(WireParameters *out, const double values[],
                                       const char *source, SmaMessage *message)
{
    return wire_parameters_from_given(out, values, NULL, source, message);
}

int wire_parameters_from_given(WireParameters *out, const double values[],
                               const unsigned char *given, const char *source,
                               SmaMessage *message)
{
    static const ParameterIndex MASS_X0[] = {PARAM_mass, PARAM_x0};
    static const ParameterIndex GEOMETRY[] = {PARAM_x0, PARAM_x_min, PARAM_diameter,
                                              PARAM_theta, PARAM_mass};
    static const ParameterIndex SURFACE[] = {PARAM_h_c, PARAM_A_s};
    static const ParameterIndex HEAT[] = {PARAM_mass, PARAM_c_p, PARAM_h_c, PARAM_A_s};
    static const ParameterIndex DOMAIN_ENERGY[] = {PARAM_nu, PARAM_eps_T};
    static const ParameterIndex STRESS[] = {PARAM_stress_max, PARAM_diameter};
    WireParameters p;
    double v[PARAM_COUNT], numbers[4], square;
    const char *failure = NULL;

    memset(&p, 0, sizeof p);
    snprintf(p.source, sizeof p.source, "%s", source != NULL ? source : "<parameters>");
    if (check_values(&p, values, given, v, message)) {
        return 1;
    }
    p.x0 = v[PARAM_x0]; p.x_min = v[PARAM_x_min]; p.diameter = v[PARAM_diameter];
    p.theta = v[PARAM_theta]; p.mass = v[PARAM_mass];
    p.R_P = v[PARAM_R_P]; p.R_M = v[PARAM_R_M]; p.R_F = v[PARAM_R_F];
    p.l_M = v[PARAM_l_M]; p.l_F = v[PARAM_l_F];
    p.a_h = v[PARAM_a_h]; p.b_h = v[PARAM_b_h]; p.a_c = v[PARAM_a_c]; p.b_c = v[PARAM_b_c];
    p.memory_depth = (int)v[PARAM_memory_depth];
    p.xi_F_inf = v[PARAM_xi_F_inf]; p.f_F = v[PARAM_f_F]; p.eps_T = v[PARAM_eps_T];
    p.nu = v[PARAM_nu]; p.eps_f = v[PARAM_eps_f]; p.nu_f = v[PARAM_nu_f];
    p.A_s = v[PARAM_A_s]; p.c_p = v[PARAM_c_p]; p.h_c = v[PARAM_h_c]; p.T_room = v[PARAM_T_room];
    p.saturation_margin = v[PARAM_saturation_margin]; p.model_load = v[PARAM_model_load];
    p.alpha = v[PARAM_alpha]; p.beta = v[PARAM_beta]; p.Kp = v[PARAM_Kp]; p.Ki = v[PARAM_Ki];
    p.T_max = v[PARAM_T_max]; p.stress_max = v[PARAM_stress_max];

    p.line_density = p.mass / p.x0;
    if (derived_failure(&p, v, "line density mass/x0", "kg/m", MASS_X0, 2, &p.line_density, 1,
                        NULL, message)) {
        return 1;
    }
    if (lattice_constants(p.x0, p.x_min, p.diameter, p.theta, p.line_density, &p.lattice,
                          &failure) == 0) {
        numbers[0] = p.lattice.N; numbers[1] = p.lattice.x_P;
        numbers[2] = p.lattice.N_l; numbers[3] = p.lattice.N_S;
    }
    if (derived_failure(&p, v, "lattice (N, x_P, N_l, N_S)", "", GEOMETRY, 5, numbers, 4,
                        failure, message)) {
        return 1;
    }
    failure = p.h_c * p.A_s == 0.0 ? SMA_DIVISION_BY_ZERO : NULL;
    if (failure == NULL) {
        p.K_th = thermal_gain(p.h_c, p.A_s);
    }
    if (derived_failure(&p, v, "thermal gain K_th = 1/(h_c A_s)", "K/W", SURFACE, 2, &p.K_th, 1,
                        failure, message)) {
        return 1;
    }
    p.tau_th = thermal_time_constant(p.mass, p.c_p, p.h_c, p.A_s);
    if (derived_failure(&p, v, "thermal time constant tau_th = m c_p/(h_c A_s)", "s", HEAT, 4,
                        &p.tau_th, 1, NULL, message)) {
        return 1;
    }
    numbers[0] = p.nu * p.eps_T / BOLTZMANN;
    if (derived_failure(&p, v, "domain energy over k_B, nu eps_T/k_B", "K", DOMAIN_ENERGY, 2, numbers,
                        1, NULL, message)) {
        return 1;
    }
    p.N = p.lattice.N;
    p.l_P = p.x_min;
    p.x_T = p.x_min - 0.5 * (p.l_M + p.l_F);
    p.x_f = p.l_F - 0.5 * (p.x_min + p.l_M);
    p.R_MF = 0.5 * (p.R_M + p.R_F);
    p.phase_lag_alpha = isnan(p.alpha) ? p.tau_th : p.alpha;  /* checked: NaN only if not given */
    square = pow(p.diameter, 2.0);
    failure = isinf(square) ? SMA_POW_OVERFLOW : NULL;
    p.load_max = p.stress_max * 1e6 * SMA_PI * square / 4.0 / STANDARD_GRAVITY;
    if (derived_failure(&p, v, "validity load limit stress_max * pi diameter^2 / 4 / g", "kg",
                        STRESS, 2, &p.load_max, 1, failure, message)) {
        return 1;
    }
    if (model_terms(&p, v, &p.terms, message)) {
        return 1;
    }
    if (!(p.R_MF > p.R_P)) {
        return sma_message_set(message, "%s: (R_M + R_F)/2 = %.17g ohm must exceed R_P = %.17g ohm: "
                               "resistance must fall as the wire transforms to P, or it cannot "
                               "sense temperature", p.source, p.R_MF, p.R_P);
    }
    if (!(p.x_f > 0.0)) {
        return sma_message_set(message, "%s: x_f = l_F - (x_min + l_M)/2 = %.17g m must be > 0: "
                               "the F phase must be the longest", p.source, p.x_f);
    }
    if (!(p.T_room > -273.15)) {
        return sma_message_set(message, "%s: parameter thermal.T_room = %.17g degC is below "
                               "absolute zero", p.source, p.T_room);
    }
    if (!(p.T_max > p.T_room)) {
        return sma_message_set(message, "%s: parameter validity.T_max = %.17g degC must exceed "
                               "thermal.T_room = %.17g degC", p.source, p.T_max, p.T_room);
    }
    *out = p;
    return 0;
}

int wire_parameters_from_values(WireParameters *out, const double values[],
                                SmaMessage *message)
{
    return wire_parameters_from_values_source(out, values, "<parameters>", message);
}
