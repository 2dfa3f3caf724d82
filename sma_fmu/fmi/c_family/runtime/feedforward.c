/* Stateful feedforward compensator; runtime/feedforward.py (see feedforward.h). */
#include "fp_contract.h"
#include "feedforward.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "checks.h"
#include "constants.h"
#include "sensing.h"
#include "state_entries.h"
#include "validity.h"

const char *const INVERSES[INVERSE_COUNT] = {"major", "minor-loop"};

int require_inverse(const char *inverse, FeedforwardInverse *out, SmaMessage *message)
{
    int index;
    if (inverse == NULL) {
        return sma_message_set(message, "inverse must be one of major, minor-loop, got None");
    }
    for (index = 0; index < INVERSE_COUNT; index++) {
        if (strcmp(inverse, INVERSES[index]) == 0) {
            *out = (FeedforwardInverse)index;
            return 0;
        }
    }
    return sma_message_set(message, "inverse must be one of major, minor-loop, got '%.200s'",
                           inverse);
}

int feedforward_stepper_init(FeedforwardStepper *self, const WireParameters *params,
                             double alpha, double beta, double model_load, int adapt_to_load,
                             const char *inverse, SmaMessage *message)
{
    FeedforwardInverse kind;
    self->reversals = NULL;
    self->reversal_count = 0;
    if (phase_lag_filter_init(&self->filter, alpha, beta, message)
        || require_nonnegative("model_load", model_load, message)
        || require_inverse(inverse, &kind, message)) {
        return 1;
    }
    /* one point more than the memory keeps: the slot a tentative push writes into */
    self->reversals = malloc(((size_t)params->memory_depth + 1) * sizeof *self->reversals);
    if (self->reversals == NULL) {
        return sma_message_set(message, "no memory for a reversal stack of %d points",
                               params->memory_depth);
    }
    self->params = *params;
    self->model_load = model_load;
    self->adapt_to_load = adapt_to_load != 0;
    self->inverse = kind;
    self->direction = HEATING;
    self->previous_reference = SMA_STATE_NONE;
    self->previous_temperature = SMA_STATE_NONE;
    self->previous_fraction = SMA_STATE_NONE;
    branch_cache_init(&self->branches);
    self->warning[0] = '\0';
    self->load_before = -HUGE_VAL;
    self->unconnected_warned = 0;
    self->bounded_before = 0;
    self->data_unwarned = params->data_range;
    return 0;
}

/* One sample's inversion (Python's _invert), no state change: *sensed, the stack after it
 * (*stack = the first of *kept points; a tentative push is written into the free slot past
 * the stack, and where it would hold more than memory_depth points *stack starts two points
 * later, as push_reversal drops the two oldest) and the xi_MF assumed. */
static int invert(FeedforwardStepper *self, double reference, double load, int direction,
                  SensedTemperature *sensed, ReversalPoint **stack, size_t *kept,
                  double *fraction, SmaMessage *message)
{
    const WireParameters *params = &self->params;
    BranchConstants constants;
    ReversalPoint *points = self->reversals;
    size_t count = self->reversal_count;
    double xi_mf, xi_p;
    if (branch_cache_get(&self->branches, params, self->adapt_to_load ? load : self->model_load,
                         direction, &constants, message)) {
        return 1;
    }
    mixed_fractions_of_resistance(reference, &constants, params, &xi_mf, &xi_p);
    if (self->inverse != INVERSE_MINOR_LOOP) {
        *stack = points;
        *kept = count;
        *fraction = xi_mf;
        return temperature_of_fractions(xi_mf, xi_p, &constants, params->saturation_margin,
                                        sensed, message);
    }
    if (direction != self->direction && !sma_state_is_none(self->previous_temperature)) {
        points[count].temperature = self->previous_temperature;   /* push_reversal */
        points[count].xi_MF = self->previous_fraction;
        count += 1;
        if (count > (size_t)params->memory_depth) {
            points += 2;
            count -= 2;
        }
    }
    *stack = points;
    return invert_on_stack(xi_mf, xi_p, &constants, direction, points, count,
                           params->saturation_margin, sensed, kept, fraction, message);
}

static int direction_for(const FeedforwardStepper *self, double reference)
{
    double previous = self->previous_reference;
    if (sma_state_is_none(previous) || reference == previous) {
        return self->direction;
    }
    return reference < previous ? HEATING : COOLING;
}

/* R_ref <= 0 [ohm] before the first R_ref > 0 (see feedforward.h)? NaN is not: the checks
 * name it. */
static int no_reference_yet(const FeedforwardStepper *self, double reference)
{
    return sma_state_is_none(self->previous_reference) && reference <= 0.0;
}

/* The outputs of a sample without a reference: P_ff = 0 W, T_ref = T_room, saturated. */
static void unconnected(const FeedforwardStepper *self, FeedforwardOutputs *outputs)
{
    outputs->P_ff = 0.0;
    outputs->T_ref = self->params.T_room;
    outputs->saturated = 1;
}

/* (T_ref [degC], saturated): the sensed temperature, bounded to validity.T_max (the
 * compensator never demands more; runtime/feedforward.py's choice). */
static void demand_of(const FeedforwardStepper *self, const SensedTemperature *sensed,
                      double *temperature, int *saturated)
{
    if (sensed->temperature > self->params.T_max) {
        *temperature = self->params.T_max;
        *saturated = 1;
    } else {
        *temperature = sensed->temperature;
        *saturated = sensed->saturated;
    }
}

/* v = (T_ref - T_room)/K_th [W]: the steady-state power of ``temperature`` [degC]. */
static double power_of(const FeedforwardStepper *self, double temperature)
{
    return (temperature - self->params.T_room) / self->params.K_th;
}

int feedforward_stepper_initial_outputs(FeedforwardStepper *self, double reference,
                                        double load, FeedforwardOutputs *outputs,
                                        SmaMessage *message)
{
    SensedTemperature sensed;
    ReversalPoint *stack;
    size_t kept;
    double fraction;
    if (phase_lag_filter_started(&self->filter)) {
        return sma_message_set(message, "initial_outputs is only defined before the first step");
    }
    if (no_reference_yet(self, reference)) {
        if (require_nonnegative("load", load, message)) {
            return 1;
        }
        unconnected(self, outputs);
        return 0;
    }
    if (require_positive("R_ref", reference, message)
        || require_nonnegative("load", load, message)
        || invert(self, reference, load, direction_for(self, reference), &sensed, &stack, &kept,
                  &fraction, message)) {
        return 1;
    }
    demand_of(self, &sensed, &outputs->T_ref, &outputs->saturated);
    outputs->P_ff = power_of(self, outputs->T_ref);
    return 0;
}

int feedforward_stepper_step(FeedforwardStepper *self, double reference, double load,
                             double step_size, FeedforwardOutputs *outputs,
                             SmaMessage *message)
{
    SensedTemperature sensed;
    ReversalPoint *stack;
    size_t kept;
    double fraction, output, temperature;
    char warning[sizeof self->warning];
    int direction, saturated, bounded, outside;
    if (no_reference_yet(self, reference)) {
        if (fast_nonnegative("load", load, message)
            || fast_positive("step_size", step_size, message)) {
            return 1;
        }
        if (self->unconnected_warned) {
            self->warning[0] = '\0';
        } else {
            snprintf(self->warning, sizeof self->warning, "R_ref = %.17g ohm before any reference "
                     "(an unconnected input): P_ff = 0 W, T_ref = T_room, saturated; the "
                     "compensator starts at the first R_ref > 0", reference);
        }
        self->unconnected_warned = 1;
        unconnected(self, outputs);
        return 0;
    }
    if (fast_positive("R_ref", reference, message) || fast_nonnegative("load", load, message)
        || fast_positive("step_size", step_size, message)) {
        return 1;
    }
    direction = direction_for(self, reference);
    if (invert(self, reference, load, direction, &sensed, &stack, &kept, &fraction, message)) {
        return 1;
    }
    warning[0] = '\0';
    if (load > self->params.load_max) {
        validity_warning(&self->params, -HUGE_VAL, -HUGE_VAL, load, self->load_before, warning,
                         sizeof warning);
    }
    demand_of(self, &sensed, &temperature, &saturated);
    bounded = temperature != sensed.temperature;
    if (bounded && !self->bounded_before) {
        size_t used = strlen(warning);
        snprintf(warning + used, sizeof warning - used, "%sT_ref = %.6g degC demanded above "
                 "validity.T_max = %g degC (R_ref = %.6g ohm, load = %.6g kg): bounded to T_max, "
                 "saturated", used ? "; " : "", sensed.temperature, self->params.T_max, reference,
                 load);
    }
    outside = self->data_unwarned
              && data_range_warning(&self->params, temperature, load, "T_ref", warning,
                                    sizeof warning);
    if (phase_lag_filter_step(&self->filter, power_of(self, temperature), step_size, &output,
                              message)) {
        return 1;
    }
    self->direction = direction;
    self->previous_reference = reference;
    if (stack != self->reversals && kept > 0) {
        memmove(self->reversals, stack, kept * sizeof *stack);
    }
    self->reversal_count = kept;
    memcpy(self->warning, warning, sizeof warning);
    self->load_before = load;
    self->bounded_before = bounded;
    if (outside) {
        self->data_unwarned = 0;
    }
    self->previous_temperature = sensed.temperature;
    self->previous_fraction = fraction;
    outputs->P_ff = output;
    outputs->T_ref = temperature;
    outputs->saturated = saturated;
    return 0;
}

size_t feedforward_stepper_state_size(const FeedforwardStepper *self)
{
    return FEEDFORWARD_STATE_FIXED + 2 * self->reversal_count;
}

void feedforward_stepper_state_write(const FeedforwardStepper *self, double *out)
{
    size_t i;
    out[0] = (double)self->direction;
    out[1] = self->previous_reference;
    out[2] = self->previous_temperature;
    out[3] = self->previous_fraction;
    phase_lag_filter_state_write(&self->filter, out + 4);
    out[6] = (double)self->reversal_count;
    for (i = 0; i < self->reversal_count; i++) {
        out[FEEDFORWARD_STATE_FIXED + 2 * i] = self->reversals[i].temperature;
        out[FEEDFORWARD_STATE_FIXED + 2 * i + 1] = self->reversals[i].xi_MF;
    }
}

int feedforward_stepper_state_read(FeedforwardStepper *self, const double *in, size_t count,
                                   SmaMessage *message)
{
    int direction, reference_present, temperature_present, fraction_present;
    double points_given;
    size_t depth = (size_t)self->params.memory_depth, points;
    if (count < FEEDFORWARD_STATE_FIXED) {
        return read_entries(count, FEEDFORWARD_STATE_FIXED, "compensator state", message);
    }
    if (read_direction(in[0], NULL, &direction, message)
        || read_optional_number(in[1], "previous_reference", 5e-324, HUGE_VAL, "ohm",
                                &reference_present, message)
        || read_temperature(in[2], "previous_temperature", HUGE_VAL, 1, &temperature_present,
                            message)
        || read_optional_number(in[3], "previous_fraction", 0.0, 1.0, "", &fraction_present,
                                message)) {
        return 1;
    }
    if (temperature_present != fraction_present) {
        return sma_message_set(message, "state entries previous_temperature and "
                               "previous_fraction must both be numbers or both be null");
    }
    points_given = in[6];
    if (!(points_given >= 0.0 && points_given <= (double)depth
          && points_given == floor(points_given))) {
        return sma_message_set(message, "reversals must be a list of at most %lu [T, xi_MF] "
                               "pairs, got a count of %.17g", (unsigned long)depth, points_given);
    }
    points = (size_t)points_given;
    if (count != FEEDFORWARD_STATE_FIXED + 2 * points) {
        return sma_message_set(message, "reversals: the compensator state holds %lu numbers, "
                               "not %d + 2 x %lu for its %lu reversal points",
                               (unsigned long)count, FEEDFORWARD_STATE_FIXED,
                               (unsigned long)points, (unsigned long)points);
    }
    if (read_points(in + FEEDFORWARD_STATE_FIXED, points, depth, "reversals", NULL,
                    message)) {
        return 1;
    }
    if (phase_lag_filter_state_read(&self->filter, in + 4, message)) {   /* the last check */
        return 1;
    }
    self->direction = direction;
    self->previous_reference = in[1];
    self->previous_temperature = in[2];
    self->previous_fraction = in[3];
    read_points(in + FEEDFORWARD_STATE_FIXED, points, depth, "reversals", self->reversals,
                NULL);
    self->reversal_count = points;
    return 0;
}

void feedforward_stepper_free(FeedforwardStepper *self)
{
    free(self->reversals);
    self->reversals = NULL;
    self->reversal_count = 0;
}
