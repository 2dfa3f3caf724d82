/* Crystal-lattice constants of the wire from its geometry (spec section 1, paper Table 1);
 * runtime/lattice.py. */
#ifndef SMA_LATTICE_H
#define SMA_LATTICE_H

/* N: unit cells [1] (two atoms per P cell); x_P: edge of the cubic P cell [m];
 * N_l: cells along the wire [1]; N_S: cells across the wire section [1]. */
typedef struct Lattice {
    double N;
    double x_P;
    double N_l;
    double N_S;
} Lattice;

/* Lattice of a wire: x0, x_min, diameter [m], theta Ti fraction [1], line_density [kg/m].
 * Returns 0, or 1 with *failure set to the text of the exception Python raises there
 * (a division by zero, or `**` overflowing); `failure` may be NULL. */
int lattice_constants(double x0, double x_min, double diameter, double theta,
                      double line_density, Lattice *out, const char **failure);

/* Python's texts for float division by zero and for `**` overflowing (errno ERANGE). */
#define SMA_DIVISION_BY_ZERO "float division by zero"
#define SMA_POW_OVERFLOW "Numerical result out of range"

#endif
