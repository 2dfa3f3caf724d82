/* The wire parameter set: its schema (name, section, unit, rule) and the validated values;
 * runtime/parameters.py. */
#ifndef SMA_PARAMETERS_H
#define SMA_PARAMETERS_H

#include "lattice.h"
#include "sma_message.h"

#include "sma_parameters_table.h"  /* generated from PARAMETER_SPECS at build time */

/* The index of each parameter in the values[] array: PARAMETER_SPECS order. */
#define SMA_PARAMETER_INDEX(name, section, unit, rule, required, low, high, range) PARAM_##name,
typedef enum {
    SMA_PARAMETER_SPECS(SMA_PARAMETER_INDEX)
    PARAM_COUNT
} ParameterIndex;
#undef SMA_PARAMETER_INDEX

#define SMA_RULE_NAME(rule, low_open, high_open) rule,
typedef enum {
    SMA_PARAMETER_RULES(SMA_RULE_NAME)
    RULE_COUNT
} ParameterRule;
#undef SMA_RULE_NAME

/* One parameter: its rule and its plausible range [low, high] in `unit` (the rule says
 * which end is open), `range` the interval as the refusal prints it, e.g. "(0, 100000]". */
typedef struct ParameterSpec {
    const char *name;
    const char *section;
    const char *unit;
    ParameterRule rule;
    int required;
    double low, high;
    const char *range;
} ParameterSpec;

extern const ParameterSpec PARAMETER_SPECS[PARAM_COUNT];

/* The optional model terms in use, defaults filled in (runtime/model_terms.py's
 * ModelTerms): nu_h, nu_c, nu2_h, nu2_c [1]; w2 [1]; a2_h, a2_c [degC] (NaN when not given);
 * b2_h, b2_c [degC/kg]; alpha_P, alpha_MF [1/K]; T_alpha [degC]; span_ratio_0,
 * span_ratio_sat [1]; span_stress [MPa] (the generated SMA_MODEL_TERMS); two_stage = w2 > 0;
 * strain: an expansion or a stress law is on; area = pi d^2/4 [m2]. */
#define SMA_TERM_FIELD(name, fallback) double name;
typedef struct ModelTerms {
    SMA_MODEL_TERMS(SMA_TERM_FIELD)
    int two_stage, strain;
    double area;
} ModelTerms;
#undef SMA_TERM_FIELD

/* Validated parameters of one SMA wire (units as in PARAMETER_SPECS), with the derived
 * constants of Python's WireParameters: lattice, N [1], line_density [kg/m], l_P [m],
 * x_T [m], x_f [m], R_MF [ohm], K_th [K/W], tau_th [s], phase_lag_alpha [s], load_max [kg],
 * load_data_min, load_data_max [kg] (the data range's stress bounds as loads, NaN when not
 * given) and data_range (1 when any bound of the data range is given).
 * alpha and the data range are NaN where Python's are None (not given). */
#define SMA_WIRE_FIELD(type, name) type name;
typedef struct WireParameters {
    SMA_WIRE_FIELDS(SMA_WIRE_FIELD)
    char source[256];

    Lattice lattice;
    double N, line_density, l_P, x_T, x_f, R_MF, K_th, tau_th, phase_lag_alpha, load_max;
    double load_data_min, load_data_max;
    int data_range;
    ModelTerms terms;
} WireParameters;
#undef SMA_WIRE_FIELD

/* Validate values[PARAM_COUNT] (PARAMETER_SPECS order; memory_depth a double holding a
 * whole number) and derive the constants, as WireParameters.from_values with
 * source "<parameters>". An optional parameter given as NaN is "not given": its default
 * (SMA_PARAMETER_DEFAULTS: memory_depth 64, stress_max 300 MPa; else None, NaN; the terms in
 * use as SMA_MODEL_TERMS). Returns 0, or 1 with the ParameterError text in `message` (which
 * names the parameter as section.name) and *out unchanged. */
int wire_parameters_from_values(WireParameters *out, const double values[],
                                SmaMessage *message);
/* The same, with the `source` that prefixes every message (e.g. "SmaActuator instance 'a'");
 * the text is copied (truncated to 255 bytes), never used as a format. */
int wire_parameters_from_values_source(WireParameters *out, const double values[],
                                       const char *source, SmaMessage *message);
/* The same with a "given" flag per parameter (PARAMETER_SPECS order): an optional parameter
 * not given takes its default, and one given must hold its rule, so a NaN or an infinity that
 * a host set is refused naming the parameter (an FMU's parameters are always given).
 * `given` NULL: NaN means "not given", as above. */
int wire_parameters_from_given(WireParameters *out, const double values[],
                               const unsigned char *given, const char *source,
                               SmaMessage *message);

#endif
