/* Temperature-sensing model: the inverse of the constant-load model (spec section 5, paper
 * eq. 31); runtime/sensing.py.
 *
 *     xi_MF = (R - R_P - xi_Fmin (R_F - R_P)) / (R_MF - R_P),   valid for 0 < xi_MF < M
 *     Lambda = ln((M - xi_MF)/xi_MF),   T_K = 1 / (1/tau_K - k_B Lambda / dH(f))
 *
 * Outside the transformation xi_MF is clamped into [delta, M - delta], delta =
 * saturation_margin * M, and `saturated` is set (also within delta of either end).
 * On the minor branches of section 6 (a stack of reversal points) the inverse walks the
 * stack: a target at or beyond the branch's end B lies on the outer branch (A and B are
 * dropped, as a closed loop is wiped out); on the branch A -> B the affine map of section 6
 * is inverted in closed form, then T from the major branch's inverse. The clamp then acts
 * twice: into the band the load allows, then into what the major branch reaches.
 *
 * A stack is `points[0 .. count)`, oldest first (Python's list, or its slice points[:count]). */
#ifndef SMA_SENSING_H
#define SMA_SENSING_H

#include <stddef.h>

#include "constant_load.h"
#include "minor_loops.h"
#include "parameters.h"
#include "sma_message.h"

/* Sensed temperature [degC] and whether the resistance was saturated (the clamp acted). */
typedef struct SensedTemperature {
    double temperature;
    int saturated;
} SensedTemperature;

/* (xi_MF, xi_P) [1] that give `resistance` [ohm] on a branch with `constants`, each as a
 * difference from its own saturated end. */
void mixed_fractions_of_resistance(double resistance, const BranchConstants *constants,
                                   const WireParameters *params, double *xi_mf, double *xi_p);
/* Lambda's tangent at a root of the two-stage search (sensing.temperature_with_tangent's
 * line): Lambda [1] and -dLambda/d(1/T_K) [K]; NaN, NaN: none. */
typedef struct TangentLine {
    double exponent;
    double slope;
} TangentLine;
#define ROOT_CAP 200              /* two_stage_root.ROOT_CAP */
#define ROOT_TOLERANCE_K 1e-14    /* two_stage_root.ROOT_TOLERANCE_K [K] */

/* 1/T_K [1/K] where a two-stage branch has (xi_MF, xi_P): a safeguarded Newton iteration on
 * Lambda(1/T_K) = ln(xi_P/xi_MF) inside the bracket of stage 1's closed form
 * (*inverse_kelvin on entry) and stage 2's (from 0 where one is <= 0; refused when the
 * branch does not reach the target at any temperature), `exponent` = ln(xi_P/xi_MF), from
 * `start` [1/K] where it lies inside the bracket (NaN: none, the search's own start), and
 * with `line` (NULL: none), Lambda's tangent at `start`, from that tangent's Newton step where
 * it lies inside the bracket; *slope is -Lambda' [K] of the last evaluation (0 where a
 * fraction underflowed). runtime/two_stage_root.py's two_stage_inverse, the same operations. */
int two_stage_inverse(double xi_mf, double xi_p, double exponent, double start,
                      const TangentLine *line, double *inverse_kelvin, double *slope,
                      const BranchConstants *constants, SmaMessage *message);
/* Invert a major branch: (xi_MF, xi_P) [1] -> *sensed; `margin` is delta/M [1]. Refuses
 * ("temperature-sensing inverse diverges at Lambda = ...") when 1/T_K would be <= 0. */
int temperature_of_fractions(double xi_mf, double xi_p, const BranchConstants *constants,
                             double margin, SensedTemperature *sensed, SmaMessage *message);
/* temperature_of_fractions with `near` [degC], a temperature close to the answer (NaN: none;
 * sensing.temperature_with_tangent's near) and `line` (NULL: none), Lambda's tangent there:
 * a two-stage search starts there (from the tangent's step) when it lies inside the bracket.
 * The same answer to the search's tolerance, not bit for bit. *tangent (NULL: not wanted)
 * gets the search's line at the answer; both NaN for one stage or an underflowed slope. */
int temperature_near(double xi_mf, double xi_p, const BranchConstants *constants, double margin,
                     double near, const TangentLine *line, SensedTemperature *sensed,
                     TangentLine *tangent, SmaMessage *message);
/* Invert the branch of the stack points[0 .. count) (count 0: the major branch of
 * `direction`) -> *sensed and *kept, how many points of the stack remain after the walk.
 * No argument checks (the compensator's hot path). */
int temperature_on_stack(double xi_mf, double xi_p, const BranchConstants *constants,
                         int direction, const ReversalPoint *points, size_t count, double margin,
                         SensedTemperature *sensed, size_t *kept, SmaMessage *message);
/* The minor-loop compensator's inversion of one sample: temperature_on_stack, the stack
 * after the walk (points[0 .. *kept)), and *assumed, the xi_MF [1] the state is assumed at:
 * `xi_mf` itself, or where the clamp acted the branch's at the clamped temperature. */
int invert_on_stack(double xi_mf, double xi_p, const BranchConstants *constants, int direction,
                    const ReversalPoint *points, size_t count, double margin,
                    SensedTemperature *sensed, size_t *kept, double *assumed,
                    SmaMessage *message);
/* Temperature [degC] of a wire with `resistance` [ohm] under `load` [kg], `direction` +1/-1,
 * on the branch of the stack reversals[0 .. count) (count 0: the major branch). Refuses a
 * bad resistance ("resistance"), direction ("direction") or load ("load"). */
int sense_temperature(double resistance, double load, int direction,
                      const WireParameters *params, const ReversalPoint *reversals,
                      size_t count, SensedTemperature *sensed, SmaMessage *message);

#endif
