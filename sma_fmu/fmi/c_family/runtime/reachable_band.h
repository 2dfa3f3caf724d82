/* The resistance band a wire can reach under a load: (R_hot(f), R_cold(f)) (spec sections
 * 4-5); runtime/reachable_band.py.
 *
 *     R_hot(f)  = R_P + xi_Fmin(f) (R_F - R_P)       all transformable lattice in P (xi_MF = 0)
 *     R_cold(f) = R_hot(f) + M(f) (R_MF - R_P)        all of it in M and F (xi_MF = M)
 *
 * The resistance of a wire under load f lies strictly inside this band, whatever its
 * temperature, direction or history. Neither end depends on the direction. */
#ifndef SMA_REACHABLE_BAND_H
#define SMA_REACHABLE_BAND_H

#include "constant_load.h"
#include "parameters.h"
#include "sma_message.h"

/* The reachable resistances at one load: hot = R_hot(f) (lowest) [ohm], cold = R_cold(f)
 * (highest) [ohm]. */
typedef struct ResistanceBand {
    double hot;
    double cold;
} ResistanceBand;

/* (R_hot, R_cold) [ohm] of a branch with `constants`. No argument checks (hot path). */
ResistanceBand band_of_branch(const BranchConstants *constants, const WireParameters *params);
/* The band [ohm] under `load` [kg]; refuses a bad load as branch_constants does. */
int reachable_band(double load, const WireParameters *params, ResistanceBand *band,
                   SmaMessage *message);

#endif
