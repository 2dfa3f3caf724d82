/* Stroke control by self-sensing: a stroke reference [m] mapped to a resistance reference R_ref
 * [ohm] through the model; runtime/stroke.py (StrokeMap), the same operations in the same
 * order, so the two agree bit for bit.
 *
 * At one load and one temperature R and x are affine in xi_MF: without thermal expansion one
 * affine solve; with it, the root of F(T) = T'(T) - T (T' the major branch's inverse at the
 * xi_MF of the affine solve at T) by one fixed-point step and then secant steps inside the
 * bracket of the branch's end temperatures. xi_MF is clamped into [delta, M - delta]: a
 * stroke beyond reach maps to the end's R_ref, `clamped` set. */
#ifndef SMA_STROKE_H
#define SMA_STROKE_H

#include "constant_load.h"
#include "parameters.h"
#include "sma_message.h"

/* R_ref [ohm], the stroke it gives [m], the branch temperature there [degC], clamped. */
typedef struct StrokeTarget {
    double R_ref;
    double stroke;
    double temperature;
    int clamped;
} StrokeTarget;

/* The map of one wire whose stroke counts from start_length x_0 [m]; no heap memory. */
typedef struct StrokeMap {
    WireParameters params;
    double start_length;
    int thermal;                       /* alpha_P or alpha_MF != 0 */
    BranchCache branches;
    int has_last;                      /* the last target, kept for an unchanged call */
    double last_stroke, last_load;
    int last_direction;
    StrokeTarget last;
    int has_ends;                      /* the end temperatures of the last branch [degC] */
    double ends_load;
    int ends_direction;
    double ends_low, ends_high;
} StrokeMap;

void stroke_map_init(StrokeMap *map, const WireParameters *params, double start_length);
/* The target of `stroke` [m] under `load` [kg] on the major branch of `direction` (+1/-1);
 * refuses a load the model does not cover as branch_constants does. */
int stroke_map_target(StrokeMap *map, double stroke, double load, int direction,
                      StrokeTarget *out, SmaMessage *message);

#endif
