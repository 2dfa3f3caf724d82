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

int domain_energy(double load, const WireParameters *params, double *energy,
                  SmaMessage *message)
{
    double value = params->nu * (params->eps_T - STANDARD_GRAVITY * load * params->x_T / params->N);
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
    double centre, xi_f_min, energy;
    if (require_nonnegative("load", load, message)) {
        return 1;
    }
    centre = hysteresis_centre(load, direction, params);
    if (!(centre < HUGE_VAL)) {
        return sma_message_set(message, "load = %.17g kg is beyond the model's range: the hysteresis "
                               "centre %.17g degC is not finite", load, centre);
    }
    if (centre <= -KELVIN_OFFSET) {
        return sma_message_set(message, "hysteresis centre %.17g degC at load %.17g kg is below 0 K",
                               centre, load);
    }
    xi_f_min = residual_f_fraction(load, params);
    if (domain_energy(load, params, &energy, message)) {
        return 1;
    }
    out->M = 1.0 - xi_f_min;
    out->xi_F_min = xi_f_min;
    out->energy_over_kB = energy / BOLTZMANN;
    out->inv_centre_K = 1.0 / (centre + KELVIN_OFFSET);
    out->centre = centre;
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

void branch_fractions(double temperature, const BranchConstants *constants, double *xi_mf,
                      double *xi_p)
{
    double exponent = constants->energy_over_kB * (
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
