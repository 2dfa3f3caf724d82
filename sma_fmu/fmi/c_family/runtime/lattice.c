/* Crystal-lattice constants; runtime/lattice.py (see lattice.h). */
#include "fp_contract.h"
#include "lattice.h"

#include <math.h>
#include <stddef.h>

#include "constants.h"

static int fail(const char **failure, const char *text)
{
    if (failure != NULL) {
        *failure = text;
    }
    return 1;
}

int lattice_constants(double x0, double x_min, double diameter, double theta,
                      double line_density, Lattice *out, const char **failure)
{
    double mean_molar_mass = theta * MOLAR_MASS_TI + (1.0 - theta) * MOLAR_MASS_NI;
    double n_cells, square, cells_4, x_p, n_l;
    if (2.0 * mean_molar_mass == 0.0) {
        return fail(failure, SMA_DIVISION_BY_ZERO);
    }
    n_cells = AVOGADRO * x0 * line_density / (2.0 * mean_molar_mass);
    square = pow(diameter, 2.0);
    if (isinf(square) && isfinite(diameter)) {
        return fail(failure, SMA_POW_OVERFLOW);
    }
    cells_4 = 4.0 * n_cells;
    if (cells_4 == 0.0) {
        return fail(failure, SMA_DIVISION_BY_ZERO);
    }
    x_p = pow(SMA_PI * square * x_min / cells_4, 1.0 / 3.0);
    if (x_p == 0.0) {
        return fail(failure, SMA_DIVISION_BY_ZERO);
    }
    n_l = x_min / x_p;
    if (n_l == 0.0) {
        return fail(failure, SMA_DIVISION_BY_ZERO);
    }
    out->N = n_cells;
    out->x_P = x_p;
    out->N_l = n_l;
    out->N_S = n_cells / n_l;
    return 0;
}
