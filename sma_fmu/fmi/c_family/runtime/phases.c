/* Phase fractions and their observables; runtime/phases.py (see phases.h). */
#include "fp_contract.h"
#include "phases.h"

#include <math.h>

#include "constants.h"

double resistance_of(PhaseFractions fractions, const WireParameters *params)
{
    return params->R_P * fractions.xi_P + params->R_M * fractions.xi_M
           + params->R_F * fractions.xi_F;
}

double length_of(PhaseFractions fractions, const WireParameters *params)
{
    return params->l_P * fractions.xi_P + params->l_M * fractions.xi_M
           + params->l_F * fractions.xi_F;
}

double configurational_entropy(PhaseFractions fractions, double n_cells)
{
    const double xi[3] = {fractions.xi_P, fractions.xi_M, fractions.xi_F};
    double total = 0.0;   /* Python's sum() starts from the int 0; 0 + a == 0.0 + a */
    int i;
    for (i = 0; i < 3; i++) {
        if (xi[i] > 0.0) {
            total = total + xi[i] * log(xi[i]);
        }
    }
    return -n_cells * BOLTZMANN * total;
}
