/* Phase fractions and the observables they determine (spec section 2); runtime/phases.py.
 *   R = R_P xi_P + R_M xi_M + R_F xi_F [ohm],  x = l_P xi_P + l_M xi_M + l_F xi_F [m],
 *   S_C = -N k_B sum(xi ln xi) [J/K] (0 ln 0 = 0). */
#ifndef SMA_PHASES_H
#define SMA_PHASES_H

#include "parameters.h"

/* Fractions of the lattice in the P, M and F phases [1]; they sum to 1. */
typedef struct PhaseFractions {
    double xi_P;
    double xi_M;
    double xi_F;
} PhaseFractions;

double resistance_of(PhaseFractions fractions, const WireParameters *params);
double length_of(PhaseFractions fractions, const WireParameters *params);
double configurational_entropy(PhaseFractions fractions, double n_cells);

#endif
