/* Phase-lag compensator Cpl(s) = (alpha s + 1)/(beta s + 1), Tustin at step h (spec
 * section 10); runtime/phase_lag.py.
 *
 *     c = 2/h,  y_k = b0 v_k + b1 v_(k-1) - a1 y_(k-1)
 *     b0 = (alpha c + 1)/(beta c + 1),  b1 = (1 - alpha c)/(beta c + 1),
 *     a1 = (1 - beta c)/(beta c + 1)
 *
 * The filter starts in steady state at its first input: v_(-1) = y_(-1) = v_0. */
#ifndef SMA_PHASE_LAG_H
#define SMA_PHASE_LAG_H

#include <stddef.h>

#include "sma_message.h"

/* (b0, b1, a1) of Cpl(s) for lead time `alpha` [s], lag time `beta` [s], step [s]. */
void tustin_coefficients(double alpha, double beta, double step_size, double *b0, double *b1,
                         double *a1);

/* Stateful Tustin realisation of Cpl(s); input and output in the same unit (here W).
 * previous_input / previous_output are SMA_STATE_NONE (NaN) before the first sample, as
 * Python's None. The step size and coefficients are a cache (not state). */
typedef struct PhaseLagFilter {
    double alpha;              /* lead time [s], >= 0 */
    double beta;               /* lag time [s], > 0 */
    double previous_input;     /* v_(k-1) [W]; NaN before the first sample */
    double previous_output;    /* y_(k-1) [W] */
    double cached_step;        /* the step b0, b1, a1 are for [s]; NaN: none yet */
    double b0, b1, a1;         /* Tustin coefficients of cached_step */
} PhaseLagFilter;

/* Checks alpha >= 0 and beta > 0 (messages name "alpha" / "beta"). */
int phase_lag_filter_init(PhaseLagFilter *self, double alpha, double beta, SmaMessage *message);
/* Has the filter taken its first sample (Python: previous_input is not None)? */
int phase_lag_filter_started(const PhaseLagFilter *self);
/* Filter one sample `value` taken at the start of a step of `step_size` [s] -> *output.
 * A non-finite output is refused ("phase-lag filter output ... is not finite"), nothing
 * changes. */
int phase_lag_filter_step(PhaseLagFilter *self, double value, double step_size, double *output,
                          SmaMessage *message);

/* Saved state: 2 doubles, [previous_input, previous_output] [W], NaN = None. */
#define PHASE_LAG_FILTER_STATE_SIZE 2
void phase_lag_filter_state_write(const PhaseLagFilter *self, double *out);
/* Checks both entries (both None or both finite numbers; messages name previous_input /
 * previous_output) and changes nothing when it refuses. */
int phase_lag_filter_state_check(const double *in, SmaMessage *message);
int phase_lag_filter_state_read(PhaseLagFilter *self, const double *in, SmaMessage *message);

#endif
