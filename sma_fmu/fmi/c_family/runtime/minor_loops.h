/* Minor loops with return-point memory: hysteresis mode "continuous" (spec section 6);
 * runtime/minor_loops.py.
 *
 * A stack of reversal points (T_i [degC], xi_i [1]), oldest first, is a ReversalPoint array
 * and a count the caller owns; an array that push_reversal may grow to `depth` points must
 * have room for depth + 1 (it appends, then drops the two oldest when above depth, as Python).
 * Branch values v: xi_MF when heating, M - xi_MF when cooling; L_d is the major branch's
 * matching value. Directions are +1 (HEATING) / -1 (COOLING). */
#ifndef SMA_MINOR_LOOPS_H
#define SMA_MINOR_LOOPS_H

#include <stddef.h>

#include "constant_load.h"
#include "sma_message.h"

#define DENOMINATOR_FLOOR 1e-12
/* DEFAULT_DEPTH (64) is in parameters.h, which Python's parameters imports from here. */

/* A reversal: the state before the step in which the direction changed, T [degC], xi_MF [1]. */
typedef struct ReversalPoint {
    double temperature;
    double xi_MF;
} ReversalPoint;

/* The branch leaving the top of the stack, as an affine map of the major branch:
 * v(T) = value_B + ratio (L_d(T) - major_B), clamped into [0, M]. */
typedef struct Branch {
    double value_B;
    double ratio;
    double major_B;
} Branch;

/* Append (temperature, xi_mf) to points[0..*count); above `depth` points drop the two oldest. */
void push_reversal(ReversalPoint *points, size_t *count, double temperature, double xi_mf,
                   size_t depth);
/* Pop closed loops (while >= 2 points and T reached or passed T_B in `direction`, drop A and
 * B); returns the number of points dropped. */
size_t wipe_out(ReversalPoint *points, size_t *count, double temperature, int direction);
/* L_d(T): the major branch's xi_MF when heating (nonzero), its xi_P when cooling [1]. */
double major_value(double temperature, const BranchConstants *constants, int heating);
/* The branch value of a stored point: xi_MF heating, M - xi_MF cooling [1]. */
double value_of(const ReversalPoint *point, double total, int heating);
/* (xi_MF, xi_P) [1] of a branch value in the direction `heating`. */
void fractions_of_value(double value, double total, int heating, double *xi_mf, double *xi_p);
/* The Branch leaving points[count - 1] (count >= 1) at the constants' load. */
Branch branch_of(const ReversalPoint *points, size_t count, const BranchConstants *constants,
                 int direction);
/* (xi_MF, xi_P) [1] at `temperature` on `branch` (NULL: the major branch). */
void fractions_on_branch(double temperature, const BranchConstants *constants, int direction,
                         const Branch *branch, double *xi_mf, double *xi_p);
/* (xi_MF, xi_P) [1] at `temperature` on the branch of the stack points[0..count). */
void fractions_on_stack(double temperature, const BranchConstants *constants, int direction,
                        const ReversalPoint *points, size_t count, double *xi_mf,
                        double *xi_p);
/* Validate a saved stack of `count` points given as 2 * count doubles (T degC, xi_MF 1 per
 * point): at most `depth` points, T finite above -273.15 degC, xi_MF in [0, 1]; refusals name
 * `name` (NULL = "reversals") and the index as Python's read_points. Only when all pass are
 * the points written to `out` (which may be NULL: validate only). */
int read_points(const double *pairs, size_t count, size_t depth, const char *name,
                ReversalPoint *out, SmaMessage *message);

#endif
