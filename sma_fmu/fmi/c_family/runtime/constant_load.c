/* Constant-load model; runtime/constant_load.py (see constant_load.h). */
#include "fp_contract.h"
#include "constant_load.h"

#include <math.h>

#include "checks.h"
#include "constants.h"

int require_temperature(const char *name, double value, SmaMessage *message)
{
    if (require_finite(name, value, message)) {
        return 1;
    }
    if (value <= -KELVIN_OFFSET) {
        return sma_message_set(message, "%s must be above -273.15 degC, got %.17g", name, value);
    }
    return 0;
}

double hysteresis_centre(double load, int direction, const WireParameters *params)
{
    if (direction == HEATING) {
        return params->a_h + params->b_h * load;
    }
    return params->a_c + params->b_c * load;
}

double residual_f_fraction(double load, const WireParameters *params)
{
    return params->xi_F_inf * (1.0 - exp(-load / params->f_F));
}

double second_centre(double load, int direction, const WireParameters *params)
{
    if (direction == HEATING) {
        return params->terms.a2_h + params->terms.b2_h * load;
    }
    return params->terms.a2_c + params->terms.b2_c * load;
}

/* A centre [degC] refused when not finite or below 0 K (`what` names it and the
 * parameters it is made of, e.g. "hysteresis centre a_h + b_h f"). */
static int checked_centre(double centre, double load, const char *what, SmaMessage *message)
{
    if (!(centre < HUGE_VAL)) {
        return sma_message_set(message, "load = %.17g kg is beyond the model's range: the %s = "
                               "%.17g degC is not finite", load, what, centre);
    }
    if (centre <= -KELVIN_OFFSET) {
        return sma_message_set(message, "%s = %.17g degC at load %.17g kg is below 0 K", what,
                               centre, load);
    }
    return 0;
}

double stress_ratio(double load, const ModelTerms *terms)
{
    double sigma = STANDARD_GRAVITY * load / terms->area / 1e6;
    return terms->span_ratio_sat + (terms->span_ratio_0 - terms->span_ratio_sat) * exp(
        -sigma / terms->span_stress);
}

double wire_length(double temperature, double xi_p, double xi_m, double xi_f, double length_m,
                   double length_f, const WireParameters *params)
{
    const ModelTerms *terms = &params->terms;
    double offset = temperature - terms->T_alpha;
    double grow = 1.0 + terms->alpha_MF * offset;
    return params->l_P * (1.0 + terms->alpha_P * offset) * xi_p
           + length_m * grow * xi_m + length_f * grow * xi_f;
}

int domain_energy(double load, const WireParameters *params, double nu, double *energy,
                  SmaMessage *message)
{
    double value = nu * (params->eps_T - STANDARD_GRAVITY * load * params->x_T / params->N);
    if (!(value < HUGE_VAL) || !(value / BOLTZMANN < HUGE_VAL)) {
        return sma_message_set(message, "load = %.17g kg is beyond the model's range: dH(f) overflows",
                               load);
    }
    if (!(value > 0.0)) {
        return sma_message_set(message, "load = %.17g kg is beyond the model's range: dH(f) = %.17g J <= 0",
                               load, value);
    }
    *energy = value;
    return 0;
}

int branch_constants(double load, int direction, const WireParameters *params,
                     BranchConstants *out, SmaMessage *message)
{
    const ModelTerms *terms = &params->terms;
    double centre, xi_f_min, energy, total, centre2, energy2, s;
    int heating = direction == HEATING;
    if (require_nonnegative("load", load, message)) {
        return 1;
    }
    centre = hysteresis_centre(load, direction, params);
    if (checked_centre(centre, load, heating ? "hysteresis centre a_h + b_h f"
                                             : "hysteresis centre a_c + b_c f", message)) {
        return 1;
    }
    xi_f_min = residual_f_fraction(load, params);
    if (domain_energy(load, params, heating ? terms->nu_h : terms->nu_c, &energy, message)) {
        return 1;
    }
    total = 1.0 - xi_f_min;
    out->M = total;
    out->xi_F_min = xi_f_min;
    out->energy_over_kB = energy / BOLTZMANN;
    out->inv_centre_K = 1.0 / (centre + KELVIN_OFFSET);
    out->centre = centre;
    out->w2 = out->M1 = out->M2 = out->energy2_over_kB = out->inv_centre2_K = 0.0;
    out->centre2 = out->length_M = out->length_F = 0.0;
    out->has_lengths = 0;
    if (terms->two_stage) {
        centre2 = second_centre(load, direction, params);
        if (checked_centre(centre2, load, heating ? "second-stage centre a2_h + b2_h f"
                                                  : "second-stage centre a2_c + b2_c f", message)
                || domain_energy(load, params, heating ? terms->nu2_h : terms->nu2_c, &energy2,
                                 message)) {
            return 1;
        }
        out->w2 = terms->w2;
        out->M1 = total * (1.0 - terms->w2);
        out->M2 = total * terms->w2;
        out->energy2_over_kB = energy2 / BOLTZMANN;
        out->inv_centre2_K = 1.0 / (centre2 + KELVIN_OFFSET);
        out->centre2 = centre2;
    }
    if (terms->strain) {
        s = stress_ratio(load, terms);
        out->length_M = params->l_P + s * (params->l_M - params->l_P);
        out->length_F = params->l_P + s * (params->l_F - params->l_P);
        out->has_lengths = 1;
    }
    return 0;
}

void logistic_split(double total, double exponent, double *first, double *second)
{
    double e;
    if (exponent > 0.0) {
        e = exp(-exponent);
        *first = total * e / (1.0 + e);
        *second = total / (1.0 + e);
        return;
    }
    e = exp(exponent);
    *first = total / (1.0 + e);
    *second = total * e / (1.0 + e);
}

void two_stage_fractions(double inverse_kelvin, const BranchConstants *constants, double *xi_mf,
                         double *xi_p)
{
    double mf1, p1, mf2, p2;
    logistic_split(constants->M1, constants->energy_over_kB * (
        constants->inv_centre_K - inverse_kelvin), &mf1, &p1);
    logistic_split(constants->M2, constants->energy2_over_kB * (
        constants->inv_centre2_K - inverse_kelvin), &mf2, &p2);
    *xi_mf = mf1 + mf2;
    *xi_p = p1 + p2;
}

void branch_fractions(double temperature, const BranchConstants *constants, double *xi_mf,
                      double *xi_p)
{
    double exponent;
    if (constants->w2 != 0.0) {
        two_stage_fractions(1.0 / (temperature + KELVIN_OFFSET), constants, xi_mf, xi_p);
        return;
    }
    exponent = constants->energy_over_kB * (
        constants->inv_centre_K - 1.0 / (temperature + KELVIN_OFFSET));
    logistic_split(constants->M, exponent, xi_mf, xi_p);
}

PhaseFractions phase_fractions(double xi_mf, double xi_p, double xi_f_min)
{
    PhaseFractions fractions;
    double half = 0.5 * xi_mf;
    fractions.xi_P = xi_p;
    fractions.xi_M = half;
    fractions.xi_F = xi_f_min + half;
    return fractions;
}

int constant_load_fractions(double temperature, double load, int direction,
                            const WireParameters *params, PhaseFractions *out,
                            SmaMessage *message)
{
    BranchConstants constants;
    double xi_mf, xi_p;
    if (require_temperature("temperature", temperature, message)
            || branch_constants(load, direction, params, &constants, message)) {
        return 1;
    }
    branch_fractions(temperature, &constants, &xi_mf, &xi_p);
    *out = phase_fractions(xi_mf, xi_p, constants.xi_F_min);
    return 0;
}

int constant_load_resistance(double temperature, double load, int direction,
                             const WireParameters *params, double *out, SmaMessage *message)
{
    PhaseFractions fractions;
    if (constant_load_fractions(temperature, load, direction, params, &fractions, message)) {
        return 1;
    }
    *out = resistance_of(fractions, params);
    return 0;
}

void branch_cache_init(BranchCache *cache)
{
    cache->count = 0;
    cache->last = -1;
}

int branch_cache_fill(BranchCache *cache, const WireParameters *params, double load, int direction,
                      BranchConstants *out, SmaMessage *message)
{
    BranchConstants constants;
    int index;
    for (index = 0; index < cache->count; index++) {
        if (cache->entries[index].load == load && cache->entries[index].direction == direction) {
            cache->last = index;
            *out = cache->entries[index].constants;
            return 0;
        }
    }
    if (branch_constants(load, direction, params, &constants, message)) {
        return 1;
    }
    if (cache->count >= BRANCH_CACHE_SIZE) {
        cache->count = 0;
    }
    index = cache->count++;
    cache->entries[index].load = load;
    cache->entries[index].direction = direction;
    cache->entries[index].constants = constants;
    cache->last = index;
    *out = constants;
    return 0;
}
