/* Phase-lag compensator Cpl(s), Tustin; runtime/phase_lag.py (see phase_lag.h). */
#include "fp_contract.h"
#include "phase_lag.h"

#include <math.h>

#include "checks.h"
#include "state_entries.h"

void tustin_coefficients(double alpha, double beta, double step_size, double *b0, double *b1,
                         double *a1)
{
    /* the formulas multiplied through by h/2: finite for every step, however small */
    double half = 0.5 * step_size;
    double denominator = beta + half;
    *b0 = (alpha + half) / denominator;
    *b1 = (half - alpha) / denominator;
    *a1 = (half - beta) / denominator;
}

int phase_lag_filter_init(PhaseLagFilter *self, double alpha, double beta, SmaMessage *message)
{
    if (require_nonnegative("alpha", alpha, message) || require_positive("beta", beta, message)) {
        return 1;
    }
    self->alpha = alpha;
    self->beta = beta;
    self->previous_input = SMA_STATE_NONE;
    self->previous_output = SMA_STATE_NONE;
    self->cached_step = SMA_STATE_NONE;
    self->b0 = self->b1 = self->a1 = 0.0;
    return 0;
}

int phase_lag_filter_started(const PhaseLagFilter *self)
{
    return !sma_state_is_none(self->previous_input);
}

int phase_lag_filter_step(PhaseLagFilter *self, double value, double step_size, double *output,
                          SmaMessage *message)
{
    double b0 = self->b0, b1 = self->b1, a1 = self->a1, result;
    int first = !phase_lag_filter_started(self);   /* steady state at the first input */
    if (!(step_size == self->cached_step)) {
        tustin_coefficients(self->alpha, self->beta, step_size, &b0, &b1, &a1);
    }
    result = (b0 * value + b1 * (first ? value : self->previous_input)
              - a1 * (first ? value : self->previous_output));
    if (!(-HUGE_VAL < result && result < HUGE_VAL)) {
        return sma_message_set(message, "phase-lag filter output %.17g W is not finite (alpha = "
                               "%.17g s, beta = %.17g s, step %.17g s)", result, self->alpha,
                               self->beta, step_size);
    }
    self->cached_step = step_size;
    self->b0 = b0;
    self->b1 = b1;
    self->a1 = a1;
    self->previous_input = value;
    self->previous_output = result;
    *output = result;
    return 0;
}

void phase_lag_filter_state_write(const PhaseLagFilter *self, double *out)
{
    out[0] = self->previous_input;
    out[1] = self->previous_output;
}

int phase_lag_filter_state_check(const double *in, SmaMessage *message)
{
    int input_present, output_present;
    if (read_optional_number(in[0], "previous_input", -HUGE_VAL, HUGE_VAL, "W", &input_present,
                             message)
        || read_optional_number(in[1], "previous_output", -HUGE_VAL, HUGE_VAL, "W",
                                &output_present, message)) {
        return 1;
    }
    if (input_present != output_present) {
        return sma_message_set(message, "filter state entries previous_input and previous_output "
                               "must both be numbers or both be null");
    }
    return 0;
}

int phase_lag_filter_state_read(PhaseLagFilter *self, const double *in, SmaMessage *message)
{
    if (phase_lag_filter_state_check(in, message)) {
        return 1;
    }
    self->previous_input = in[0];
    self->previous_output = in[1];
    return 0;
}
