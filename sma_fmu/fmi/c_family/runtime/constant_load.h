/* Constant-load model with a direction-switched hysteresis centre (spec sections 3-4);
 * runtime/constant_load.py.
 *   tau(f, d) = a_h + b_h f (heating), a_c + b_c f (cooling)   [degC]
 *   (cc_share_d > 0: the strain-weighted load f_d of centre_load in place of f)
 *   xi_Fmin(f) = xi_F_inf (1 - exp(-f/f_F)),  dH(f) = nu (eps_T - g f x_T / N)  [J]
 *   Lambda = (dH/k_B)(1/tau_K - 1/T_K),  xi_MF = M/(1 + e^Lambda),  xi_P = M - xi_MF
 * With the optional model terms (runtime/model_terms.py): dH with nu_h / nu_c, a second stage
 * xi_MF = M (1 - w2)/(1 + e^Lambda1) + M w2/(1 + e^Lambda2), the stress law and expansion. */
#ifndef SMA_CONSTANT_LOAD_H
#define SMA_CONSTANT_LOAD_H

#include "parameters.h"
#include "phases.h"
#include "sma_message.h"

/* Constants of one major branch at one load: M = 1 - xi_Fmin [1], xi_F_min [1],
 * energy_over_kB = dH/k_B [K] (nu_d of the direction), inv_centre_K = 1/tau_K [1/K],
 * centre = tau [degC]; the second stage (w2 > 0, else w2 = 0 and the rest 0): M1 = M (1 - w2),
 * M2 = M w2 [1], energy2_over_kB [K], inv_centre2_K [1/K], centre2 [degC]; the strain terms
 * (has_lengths): length_M, length_F = l_P + s(sigma) (l_i - l_P) [m] at T_alpha. */
typedef struct BranchConstants {
    double M;
    double xi_F_min;
    double energy_over_kB;
    double inv_centre_K;
    double centre;
    double w2, M1, M2, energy2_over_kB, inv_centre2_K, centre2;
    int has_lengths;
    double length_M, length_F;
} BranchConstants;

/* `value` [degC] finite and above absolute zero, else refused naming `name`. */
int require_temperature(const char *name, double value, SmaMessage *message);
/* f_d [kg] = f [1 + c (s_0/s_sat - 1) phi(sigma/span_stress)], phi(x) = (1 - e^-x)/x,
 * phi(0) = 1: the load a centre's slope multiplies when the share `share` [1] of it follows
 * the transformation strain (model_terms.centre_load). */
double centre_load(double load, double share, const ModelTerms *terms);
/* The load [kg] the centres' slopes multiply in `direction`: `load`, or centre_load with
 * cc_share_d > 0 (constant_load.slope_load). */
double slope_load(double load, int direction, const WireParameters *params);
/* Hysteresis centre tau [degC] = a_d + b_d slope_load for a load [kg] and direction
 * (+1 heating, -1 cooling). */
double hysteresis_centre(double load, int direction, const WireParameters *params);
/* Residual F fraction xi_Fmin(f) [1]. */
double residual_f_fraction(double load, const WireParameters *params);
/* Second-stage centre tau2 [degC] = a2_d + b2_d slope_load. */
double second_centre(double load, int direction, const WireParameters *params);
/* dH(f) [J] with domain size `nu` [1] -> *energy; refused when it overflows or is <= 0. */
int domain_energy(double load, const WireParameters *params, double nu, double *energy,
                  SmaMessage *message);
/* s(sigma) [1] of the stress law at `load` [kg] (model_terms.stress_ratio). */
double stress_ratio(double load, const ModelTerms *terms);
/* x [m] at `temperature` [degC] with the strain terms (model_terms.wire_length). */
double wire_length(double temperature, double xi_p, double xi_m, double xi_f, double length_m,
                   double length_f, const WireParameters *params);
/* The BranchConstants for `load` [kg] and `direction`; refused as Python's ValueError. */
int branch_constants(double load, int direction, const WireParameters *params,
                     BranchConstants *out, SmaMessage *message);
/* Split `total` into (total/(1+e^z), total e^z/(1+e^z)) without overflow. */
void logistic_split(double total, double exponent, double *first, double *second);
/* (xi_MF, xi_P) [1] of a two-stage branch at 1/T_K = `inverse_kelvin` [1/K]. */
void two_stage_fractions(double inverse_kelvin, const BranchConstants *constants, double *xi_mf,
                         double *xi_p);
/* (xi_MF, xi_P) [1] on a major branch at `temperature` [degC] (no argument checks). */
void branch_fractions(double temperature, const BranchConstants *constants, double *xi_mf,
                      double *xi_p);
/* PhaseFractions from xi_MF, xi_P and the residual F (xi_M = xi_F'). */
PhaseFractions phase_fractions(double xi_mf, double xi_p, double xi_f_min);
int constant_load_fractions(double temperature, double load, int direction,
                            const WireParameters *params, PhaseFractions *out,
                            SmaMessage *message);
int constant_load_resistance(double temperature, double load, int direction,
                             const WireParameters *params, double *out, SmaMessage *message);

/* Memo of branch_constants per (load, direction) for steppers (Python's BranchCache, same
 * numbers): the last entry is checked first; the memo is emptied when it holds
 * BRANCH_CACHE_SIZE entries. No heap memory and no pointers (a stepper may be copied): the
 * caller passes the parameters at each get. */
#define BRANCH_CACHE_SIZE 64
typedef struct BranchCacheEntry {
    double load;
    int direction;
    BranchConstants constants;
} BranchCacheEntry;
typedef struct BranchCache {
    int count;
    int last;                         /* index of the last entry returned, -1: none */
    BranchCacheEntry entries[BRANCH_CACHE_SIZE];
} BranchCache;

void branch_cache_init(BranchCache *cache);
/* branch_cache_get when the last entry is not the one: the memo's search, else a new entry. */
int branch_cache_fill(BranchCache *cache, const WireParameters *params, double load, int direction,
                      BranchConstants *out, SmaMessage *message);
/* The constants for `load` [kg] and `direction` (+1/-1) -> *out (a copy); the last entry's
 * hit, every step's case, is inline. */
SMA_INLINE int branch_cache_get(BranchCache *cache, const WireParameters *params, double load,
                                int direction, BranchConstants *out, SmaMessage *message)
{
    if (cache->last >= 0) {
        const BranchCacheEntry *last = &cache->entries[cache->last];
        if (load == last->load && direction == last->direction) {
            *out = last->constants;
            return 0;
        }
    }
    return branch_cache_fill(cache, params, load, direction, out, message);
}

#endif
