/* The wire parameter set: its schema (name, section, unit, rule) and the validated values;
 * runtime/parameters.py. */
#ifndef SMA_PARAMETERS_H
#define SMA_PARAMETERS_H

#include "lattice.h"
#include "sma_message.h"

#define DEFAULT_DEPTH 64              /* minor_loops.DEFAULT_DEPTH */
#define MAX_MEMORY_DEPTH 100000
#define DEFAULT_STRESS_MAX 300.0      /* MPa */

/* PARAMETER_SPECS order: the index of each parameter in the values[] array. */
typedef enum {
    PARAM_x0, PARAM_x_min, PARAM_diameter, PARAM_theta, PARAM_mass,
    PARAM_R_P, PARAM_R_M, PARAM_R_F, PARAM_l_M, PARAM_l_F,
    PARAM_a_h, PARAM_b_h, PARAM_a_c, PARAM_b_c, PARAM_memory_depth,
    PARAM_xi_F_inf, PARAM_f_F, PARAM_eps_T, PARAM_nu, PARAM_nu_h, PARAM_nu_c,
    PARAM_w2, PARAM_a2_h, PARAM_b2_h, PARAM_a2_c, PARAM_b2_c, PARAM_nu2_h, PARAM_nu2_c,
    PARAM_alpha_P, PARAM_alpha_MF, PARAM_T_alpha, PARAM_span_ratio_0, PARAM_span_ratio_sat,
    PARAM_span_stress, PARAM_eps_f, PARAM_nu_f,
    PARAM_A_s, PARAM_c_p, PARAM_h_c, PARAM_T_room, PARAM_saturation_margin,
    PARAM_model_load, PARAM_alpha, PARAM_beta, PARAM_Kp, PARAM_Ki, PARAM_T_max,
    PARAM_stress_max,
    PARAM_COUNT
} ParameterIndex;

typedef enum {
    RULE_POSITIVE, RULE_NONNEGATIVE, RULE_FRACTION, RULE_FINITE, RULE_MARGIN, RULE_DEPTH
} ParameterRule;

typedef struct ParameterSpec {
    const char *name;
    const char *section;
    const char *unit;
    ParameterRule rule;
    int required;
} ParameterSpec;

extern const ParameterSpec PARAMETER_SPECS[PARAM_COUNT];

#define DEFAULT_T_ALPHA 20.0          /* degC; model_terms.DEFAULT_T_ALPHA */
#define DEFAULT_SPAN_STRESS 100.0     /* MPa; model_terms.DEFAULT_SPAN_STRESS */

/* The optional terms of issue 36 in use, defaults filled in (runtime/model_terms.py's
 * ModelTerms): nu_h, nu_c, nu2_h, nu2_c [1]; w2 [1]; a2_h, a2_c [degC] (NaN when not given);
 * b2_h, b2_c [degC/kg]; alpha_P, alpha_MF [1/K]; T_alpha [degC]; span_ratio_0,
 * span_ratio_sat [1]; span_stress [MPa]; two_stage = w2 > 0; strain: an expansion or a
 * stress law is on; area = pi d^2/4 [m2]. */
typedef struct ModelTerms {
    double nu_h, nu_c, w2, a2_h, b2_h, a2_c, b2_c, nu2_h, nu2_c;
    double alpha_P, alpha_MF, T_alpha, span_ratio_0, span_ratio_sat, span_stress;
    int two_stage, strain;
    double area;
} ModelTerms;

/* Validated parameters of one SMA wire (units as in PARAMETER_SPECS), with the derived
 * constants of Python's WireParameters: lattice, N [1], line_density [kg/m], l_P [m],
 * x_T [m], x_f [m], R_MF [ohm], K_th [K/W], tau_th [s], phase_lag_alpha [s], load_max [kg].
 * alpha is NaN where Python's is None (not given). */
typedef struct WireParameters {
    double x0, x_min, diameter, theta, mass;
    double R_P, R_M, R_F, l_M, l_F;
    double a_h, b_h, a_c, b_c;
    double xi_F_inf, f_F, eps_T, nu, eps_f, nu_f;
    double A_s, c_p, h_c, T_room;
    double saturation_margin, model_load, beta, Kp, Ki, T_max;
    double alpha;
    int memory_depth;
    double stress_max;
    char source[256];

    Lattice lattice;
    double N, line_density, l_P, x_T, x_f, R_MF, K_th, tau_th, phase_lag_alpha, load_max;
    ModelTerms terms;
} WireParameters;

/* Validate values[PARAM_COUNT] (PARAMETER_SPECS order; memory_depth a double holding a
 * whole number) and derive the constants, as WireParameters.from_values with
 * source "<parameters>". An optional parameter (memory_depth, alpha, stress_max) given as NaN
 * is "not given": its default (64, None, 300 MPa; the terms of ModelTerms as model_terms.py). Returns 0, or 1 with the ParameterError
 * text in `message` (which names the parameter as section.name) and *out unchanged. */
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
