/* The wire parameter set; runtime/parameters.py (see parameters.h). */
#include "fp_contract.h"
#include "parameters.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "constants.h"
#include "thermal.h"

#define SMA_SPEC_ROW(name, section, unit, rule, required, low, high, range) \
    {#name, section, unit, rule, required, low, high, range},
const ParameterSpec PARAMETER_SPECS[PARAM_COUNT] = {
    SMA_PARAMETER_SPECS(SMA_SPEC_ROW)
};
#undef SMA_SPEC_ROW

/* Whether each rule's range is open at its low and its high end. */
#define SMA_RULE_ENDS(rule, low_open, high_open) {low_open, high_open},
static const unsigned char RULE_OPEN[RULE_COUNT][2] = {
    SMA_PARAMETER_RULES(SMA_RULE_ENDS)
};
#undef SMA_RULE_ENDS

/* value_in_range of parameters.py: the rule holds and the value lies in the spec's range. */
static int value_in_range(const ParameterSpec *spec, double value)
{
    const unsigned char *open = RULE_OPEN[spec->rule];
    if (!isfinite(value) || (spec->rule == RULE_DEPTH && value != trunc(value))) {
        return 0;
    }
    return (open[0] ? spec->low < value : spec->low <= value)
           && (open[1] ? value < spec->high : value <= spec->high);
}

/* requirement_text of parameters.py, without the range: the words before it. */
static const char *requirement_words(const ParameterSpec *spec, double value)
{
    if (spec->rule == RULE_DEPTH) {
        return "a whole number in ";
    }
    return isfinite(value) ? "in " : "a finite number in ";
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
#define SMA_TERM_IN_USE(name, fallback) t->name = value_or(v[PARAM_##name], fallback);
    SMA_MODEL_TERMS(SMA_TERM_IN_USE)
#undef SMA_TERM_IN_USE
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
    t->two_stage = t->w2 > 0.0;
    t->strain = t->alpha_P != 0.0 || t->alpha_MF != 0.0 || t->span_ratio_0 != 1.0
                || t->span_ratio_sat != 1.0;
    t->area = SMA_PI * p->diameter * p->diameter / 4.0;
    return 0;
}

/* The default of the optional parameter `index` not given: 1 with *value, or 0 when it
 * has none (None: NaN). */
static int default_of(int index, double *value)
{
#define SMA_DEFAULT_OF(name, number) \
    if (index == PARAM_##name) {     \
        *value = number;             \
        return 1;                    \
    }
    SMA_PARAMETER_DEFAULTS(SMA_DEFAULT_OF)
#undef SMA_DEFAULT_OF
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
        if (!spec->required && (given != NULL ? !given[index] : isnan(value))
                && !default_of(index, &value)) {
            checked[index] = NAN;     /* alpha and the terms: None (NaN below) */
            continue;
        }
        if (!value_in_range(spec, value)) {
            return sma_message_set(message, "%s: parameter %s.%s = %.17g must be %s%s [%s]",
                                   p->source, spec->section, spec->name, value,
                                   requirement_words(spec, value), spec->range, spec->unit);
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
#define SMA_COPY_FIELD(type, name) p.name = (type)v[PARAM_##name];
    SMA_WIRE_FIELDS(SMA_COPY_FIELD)
#undef SMA_COPY_FIELD

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
    /* the data range's stress bounds as loads, as load_max (NaN stays NaN: not given) */
    p.load_data_min = p.stress_data_min * 1e6 * SMA_PI * square / 4.0 / STANDARD_GRAVITY;
    p.load_data_max = p.stress_data_max * 1e6 * SMA_PI * square / 4.0 / STANDARD_GRAVITY;
    p.data_range = !isnan(p.T_data_min) || !isnan(p.T_data_max) || !isnan(p.stress_data_min)
                   || !isnan(p.stress_data_max);
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
    if (p.T_data_min > p.T_data_max) {
        return sma_message_set(message, "%s: parameter validity.T_data_min = %.17g degC must be <= "
                               "validity.T_data_max = %.17g degC", p.source, p.T_data_min,
                               p.T_data_max);
    }
    if (p.stress_data_min > p.stress_data_max) {
        return sma_message_set(message, "%s: parameter validity.stress_data_min = %.17g MPa must be "
                               "<= validity.stress_data_max = %.17g MPa", p.source,
                               p.stress_data_min, p.stress_data_max);
    }
    *out = p;
    return 0;
}

int wire_parameters_from_values(WireParameters *out, const double values[],
                                SmaMessage *message)
{
    return wire_parameters_from_values_source(out, values, "<parameters>", message);
}
