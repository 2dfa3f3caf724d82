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
                             const char *inverse, const char *shaping, double power_cap,
                             SmaMessage *message)
{
    FeedforwardInverse kind;
    FeedforwardShaping shaped;
    self->reversals = NULL;
    self->reversal_count = 0;
    self->shaping = SHAPING_NONE;
    if (phase_lag_filter_init(&self->filter, alpha, beta, message)
        || require_nonnegative("model_load", model_load, message)
        || require_inverse(inverse, &kind, message)
        || require_shaping(shaping, &shaped, message)
        || require_power_cap(power_cap, shaped, message)) {
        return 1;
    }
    if (shaped == SHAPING_REACHABLE
        && reachable_shaping_init(&self->shaper, params, kind == INVERSE_MINOR_LOOP, power_cap,
                                  model_load, message)) {
        return 1;
    }
    /* one point more than the memory keeps: the slot a tentative push writes into */
    self->reversals = malloc(((size_t)params->memory_depth + 1) * sizeof *self->reversals);
    if (self->reversals == NULL) {
        if (shaped == SHAPING_REACHABLE) {
            reachable_shaping_free(&self->shaper);
        }
        return sma_message_set(message, "no memory for a reversal stack of %d points",
                               params->memory_depth);
    }
    self->shaping = shaped;
    self->params = *params;
    self->model_load = model_load;
    self->adapt_to_load = adapt_to_load != 0;
    self->inverse = kind;
    self->direction = HEATING;
    self->previous_reference = SMA_STATE_NONE;
    self->previous_temperature = SMA_STATE_NONE;
    self->previous_fraction = SMA_STATE_NONE;
    self->previous_line.exponent = SMA_STATE_NONE;
    self->previous_line.slope = SMA_STATE_NONE;
    branch_cache_init(&self->branches);
    self->warning[0] = '\0';
    self->load_before = -HUGE_VAL;
    self->unconnected_warned = 0;
    self->bounded_before = 0;
    self->data_unwarned = params->data_range;
    self->anticipation = 0.0;
    self->earlier_reference = SMA_STATE_NONE;
    self->last_reference = SMA_STATE_NONE;
    self->held_aim = SMA_STATE_NONE;
    return 0;
}

int feedforward_stepper_set_anticipation(FeedforwardStepper *self, double lead,
                                         SmaMessage *message)
{
    if (require_nonnegative("anticipation", lead, message)) {
        return 1;
    }
    if (lead > 0.0 && self->shaping != SHAPING_REACHABLE) {
        return sma_message_set(message, "anticipation = %.17g s needs shaping 'reachable', "
                               "got 'none'", lead);
    }
    self->anticipation = lead;
    return 0;
}

/* runtime/anticipation.py's TurnAnticipation: the aim [ohm] for the sample `reference` and
 * the aim to hold after it (*held; NaN = None), no state change. */
static double anticipated_aim(const FeedforwardStepper *self, double reference,
                              double step_size, double *held)
{
    double earlier = self->earlier_reference, previous = self->last_reference;
    double lead = self->anticipation, aim = reference, slope, curvature;
    if (earlier == earlier) {
        slope = (reference - earlier) / (2.0 * step_size);
        curvature = (reference - 2.0 * previous + earlier) / (step_size * step_size);
        if (slope < 0.0 && 0.0 < curvature && step_size * curvature <= -slope
            && -slope < curvature * lead) {
            aim = reference + slope * lead + 0.5 * curvature * lead * lead;
        }
    }
    if (aim == reference && self->held_aim == self->held_aim && reference < self->held_aim) {
        *held = self->held_aim;
        return self->held_aim;
    }
    *held = aim == reference ? SMA_STATE_NONE : aim;
    return aim;
}

/* One sample's inversion (Python's _invert), no state change: *sensed, the stack after it
 * (*stack = the first of *kept points; a tentative push is written into the free slot past
 * the stack, and where it would hold more than memory_depth points *stack starts two points
 * later, as push_reversal drops the two oldest) and the xi_MF assumed. The memory is the
 * compensator's or, shaped, the model wire's (its stack has the same free slot). */
static int invert(FeedforwardStepper *self, double reference, double load, int direction,
                  SensedTemperature *sensed, ReversalPoint **stack, size_t *kept,
                  double *fraction, TangentLine *tangent, SmaMessage *message)
{
    const WireParameters *params = &self->params;
    BranchConstants constants;
    ReversalPoint *points = self->reversals;
    size_t count = self->reversal_count;
    int last = self->direction;
    double xi_mf, xi_p, temperature = self->previous_temperature;
    double assumed = self->previous_fraction;
    const TangentLine *line = sma_state_is_none(self->previous_line.slope)
                              ? NULL : &self->previous_line;
    tangent->exponent = tangent->slope = NAN;
    if (self->shaping == SHAPING_REACHABLE) {
        const PlantStepper *model = &self->shaper.model;
        points = model->reversals;
        count = model->reversal_count;
        last = model->direction;
        temperature = model->temperature;
        assumed = model->xi_MF;
        line = NULL;   /* the model's temperature is not the last root */
    }
    if (branch_cache_get(&self->branches, params, self->adapt_to_load ? load : self->model_load,
                         direction, &constants, message)) {
        return 1;
    }
    mixed_fractions_of_resistance(reference, &constants, params, &xi_mf, &xi_p);
    if (self->inverse != INVERSE_MINOR_LOOP) {
        *stack = points;
        *kept = count;
        *fraction = xi_mf;
        /* the search starts at the last T on the same branch (NaN: none), from its tangent */
        return direction == last
               ? temperature_near(xi_mf, xi_p, &constants, params->saturation_margin,
                                  temperature, line, sensed, tangent, message)
               : temperature_near(xi_mf, xi_p, &constants, params->saturation_margin,
                                  NAN, NULL, sensed, tangent, message);
    }
    if (direction != last && !sma_state_is_none(temperature)) {
        points[count].temperature = temperature;   /* push_reversal */
        points[count].xi_MF = assumed;
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

/* The shaped compensator's demand (Python's _shaped_demand), no state change: *way, where
 * its model wire moves, and *sensed, the inverse it aims at. Minor-loop: the way that brings
 * the model's xi_MF towards R_ref's (equal keeps the model's direction), and where that
 * branch's inverse lies behind the model, the major branch's when it lies ahead. Major: d_ref. */
static int shaped_demand(FeedforwardStepper *self, double reference, double load, int direction,
                         int *way, SensedTemperature *sensed, SmaMessage *message)
{
    const WireParameters *params = &self->params;
    const PlantStepper *model = &self->shaper.model;
    double used = self->adapt_to_load ? load : self->model_load, target, xi_mf, xi_p, fraction;
    BranchConstants constants;
    SensedTemperature major;
    ReversalPoint *stack;
    size_t kept;
    TangentLine line;
    if (self->inverse != INVERSE_MINOR_LOOP) {
        *way = direction;
        return invert(self, reference, load, direction, sensed, &stack, &kept, &fraction, &line,
                      message);
    }
    if (branch_cache_get(&self->branches, params, used, HEATING, &constants, message)) {
        return 1;
    }
    mixed_fractions_of_resistance(reference, &constants, params, &target, &xi_p);
    *way = target < model->xi_MF ? HEATING : target > model->xi_MF ? COOLING : model->direction;
    if (invert(self, reference, load, *way, sensed, &stack, &kept, &fraction, &line,
               message)) {
        return 1;
    }
    if (reachable_shaping_ahead(&self->shaper, sensed->temperature, *way)) {
        return 0;
    }
    if (branch_cache_get(&self->branches, params, used, *way, &constants, message)) {
        return 1;
    }
    mixed_fractions_of_resistance(reference, &constants, params, &xi_mf, &xi_p);
    if (temperature_of_fractions(xi_mf, xi_p, &constants, params->saturation_margin, &major,
                                 message)) {
        return 1;
    }
    if (reachable_shaping_ahead(&self->shaper, major.temperature, *way)) {
        *sensed = major;
    }
    return 0;
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
    TangentLine line;
    ReversalPoint *stack;
    size_t kept;
    double fraction;
    int way;
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
        || require_nonnegative("load", load, message)) {
        return 1;
    }
    if (self->shaping == SHAPING_REACHABLE
        ? shaped_demand(self, reference, load, direction_for(self, reference), &way, &sensed,
                        message)
        : invert(self, reference, load, direction_for(self, reference), &sensed, &stack, &kept,
                 &fraction, &line, message)) {
        return 1;
    }
    demand_of(self, &sensed, &outputs->T_ref, &outputs->saturated);
    if (self->shaping == SHAPING_REACHABLE) {   /* the model has not moved: its temperature */
        double demand = outputs->T_ref;
        reachable_shaping_resting(&self->shaper, &outputs->P_ff, &outputs->T_ref);
        outputs->saturated = outputs->saturated || demand != outputs->T_ref;
        return 0;
    }
    outputs->P_ff = power_of(self, outputs->T_ref);
    return 0;
}

int feedforward_stepper_step(FeedforwardStepper *self, double reference, double load,
                             double step_size, FeedforwardOutputs *outputs,
                             SmaMessage *message)
{
    SensedTemperature sensed;
    TangentLine line;
    ReversalPoint *stack;
    size_t kept;
    double fraction, output, temperature, sample, held = SMA_STATE_NONE;
    char warning[sizeof self->warning];
    int direction, way, saturated, bounded, outside, moved;
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
    sample = reference;   /* R_ref,k; the compensator works on the aim (anticipation) */
    if (self->anticipation > 0.0) {
        reference = anticipated_aim(self, sample, step_size, &held);
    }
    direction = direction_for(self, reference);
    if (self->shaping == SHAPING_REACHABLE
        ? shaped_demand(self, reference, load, direction, &way, &sensed, message)
        : invert(self, reference, load, direction, &sensed, &stack, &kept, &fraction, &line,
                 message)) {
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
    if (self->shaping == SHAPING_REACHABLE) {
        if (reachable_shaping_step(&self->shaper, temperature, way,
                                   self->adapt_to_load ? load : self->model_load, step_size,
                                   &output, &temperature, &moved, message)) {
            return 1;
        }
        saturated = saturated || moved;
    } else {
        if (phase_lag_filter_step(&self->filter, power_of(self, temperature), step_size,
                                  &output, message)) {
            return 1;
        }
        if (stack != self->reversals && kept > 0) {
            memmove(self->reversals, stack, kept * sizeof *stack);
        }
        self->reversal_count = kept;
        self->previous_temperature = sensed.temperature;
        self->previous_fraction = fraction;
        self->previous_line = line;
    }
    if (self->anticipation > 0.0) {
        self->earlier_reference = self->last_reference;
        self->last_reference = sample;
        self->held_aim = held;
    }
    self->direction = direction;
    self->previous_reference = reference;
    memcpy(self->warning, warning, sizeof warning);
    self->load_before = load;
    self->bounded_before = bounded;
    if (outside) {
        self->data_unwarned = 0;
    }
    outputs->P_ff = output;
    outputs->T_ref = temperature;
    outputs->saturated = saturated;
    return 0;
}

size_t feedforward_stepper_state_size(const FeedforwardStepper *self)
{
    size_t own = FEEDFORWARD_STATE_FIXED + 2 * self->reversal_count
                 + (self->anticipation > 0.0 ? 3 : 0);
    return self->shaping == SHAPING_REACHABLE
           ? own + plant_stepper_state_size(&self->shaper.model) : own;
}

void feedforward_stepper_state_write(const FeedforwardStepper *self, double *out)
{
    size_t i;
    out[0] = (double)self->direction;
    out[1] = self->previous_reference;
    out[2] = self->previous_temperature;
    out[3] = self->previous_fraction;
    phase_lag_filter_state_write(&self->filter, out + 4);
    out[6] = self->previous_line.exponent;
    out[7] = self->previous_line.slope;
    out[8] = (double)self->reversal_count;
    for (i = 0; i < self->reversal_count; i++) {
        out[FEEDFORWARD_STATE_FIXED + 2 * i] = self->reversals[i].temperature;
        out[FEEDFORWARD_STATE_FIXED + 2 * i + 1] = self->reversals[i].xi_MF;
    }
    out += FEEDFORWARD_STATE_FIXED + 2 * self->reversal_count;
    if (self->anticipation > 0.0) {
        out[0] = self->earlier_reference;
        out[1] = self->last_reference;
        out[2] = self->held_aim;
        out += 3;
    }
    if (self->shaping == SHAPING_REACHABLE) {
        plant_stepper_state_write(&self->shaper.model, out);
    }
}

/* The model wire of a saved state, `count` doubles at `in`, checked on a new model (*model,
 * allocated when this returns 0); refused as Python's "state entry model: ..." */
static int read_model(const FeedforwardStepper *self, const double *in, size_t count,
                      ReachableShaping *model, SmaMessage *message)
{
    SmaMessage reason;
    if (reachable_shaping_init(model, &self->params, self->inverse == INVERSE_MINOR_LOOP,
                               self->shaper.power_cap, self->model_load, message)) {
        return 1;
    }
    if (plant_stepper_state_read(&model->model, in, count, &reason)) {
        reachable_shaping_free(model);
        return sma_message_set(message, "state entry model: %s", reason.text);
    }
    return 0;
}

int feedforward_stepper_state_read(FeedforwardStepper *self, const double *in, size_t count,
                                   SmaMessage *message)
{
    int direction, reference_present, temperature_present, fraction_present, exponent_present;
    int slope_present;
    int shaped = self->shaping == SHAPING_REACHABLE, present;
    size_t anticipated = self->anticipation > 0.0 ? 3 : 0, i;
    static const char *const entries[3] = {"earlier", "previous", "held"};
    SmaMessage reason;
    double points_given;
    ReachableShaping model;
    size_t depth = (size_t)self->params.memory_depth, points, own;
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
    if (read_optional_number(in[6], "previous_exponent", -HUGE_VAL, HUGE_VAL, "",
                             &exponent_present, message)
        || read_optional_number(in[7], "previous_slope", 5e-324, HUGE_VAL, "K", &slope_present,
                                message)) {
        return 1;
    }
    if (exponent_present != slope_present) {
        return sma_message_set(message, "state entries previous_exponent and previous_slope "
                               "must both be numbers or both be null");
    }
    points_given = in[8];
    if (!(points_given >= 0.0 && points_given <= (double)depth
          && points_given == floor(points_given))) {
        return sma_message_set(message, "reversals must be a list of at most %lu [T, xi_MF] "
                               "pairs, got a count of %.17g", (unsigned long)depth, points_given);
    }
    points = (size_t)points_given;
    own = FEEDFORWARD_STATE_FIXED + 2 * points + anticipated;
    if (shaped ? count < own : count != own) {
        return sma_message_set(message, "reversals: the compensator state holds %lu numbers, "
                               "not %d + 2 x %lu for its %lu reversal points%s%s",
                               (unsigned long)count, FEEDFORWARD_STATE_FIXED,
                               (unsigned long)points, (unsigned long)points,
                               anticipated ? ", 3 of the anticipation" : "",
                               shaped ? " and the model wire's state" : "");
    }
    if (read_points(in + FEEDFORWARD_STATE_FIXED, points, depth, "reversals", NULL,
                    message)) {
        return 1;
    }
    for (i = 0; i < anticipated; i++) {
        if (read_optional_number(in[own - 3 + i], entries[i], 5e-324, HUGE_VAL, "ohm",
                                 &present, &reason)) {
            return sma_message_set(message, "state entry anticipation: %s", reason.text);
        }
    }
    if (shaped && read_model(self, in + own, count - own, &model, message)) {
        return 1;
    }
    if (phase_lag_filter_state_read(&self->filter, in + 4, message)) {   /* the last check */
        if (shaped) {
            reachable_shaping_free(&model);
        }
        return 1;
    }
    if (shaped) {   /* taken only now that everything is good */
        reachable_shaping_free(&self->shaper);
        self->shaper = model;
    }
    self->direction = direction;
    self->previous_reference = in[1];
    self->previous_temperature = in[2];
    self->previous_fraction = in[3];
    self->previous_line.exponent = in[6];
    self->previous_line.slope = in[7];
    if (anticipated) {
        self->earlier_reference = in[own - 3];
        self->last_reference = in[own - 2];
        self->held_aim = in[own - 1];
    }
    read_points(in + FEEDFORWARD_STATE_FIXED, points, depth, "reversals", self->reversals,
                NULL);
    self->reversal_count = points;
    return 0;
}

void feedforward_stepper_free(FeedforwardStepper *self)
{
    if (self->shaping == SHAPING_REACHABLE) {
        reachable_shaping_free(&self->shaper);
        self->shaping = SHAPING_NONE;
    }
    free(self->reversals);
    self->reversals = NULL;
    self->reversal_count = 0;
}
