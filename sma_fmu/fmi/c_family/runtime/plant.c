/* Stateful plant; runtime/plant.py (see plant.h). */
#include "fp_contract.h"
#include "plant.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "constants.h"
#include "state_entries.h"
#include "thermal.h"
#include "validity.h"

/* The outputs of the present state into stepper->outputs (written in place: no copy). */
static void evaluate(PlantStepper *stepper, const BranchConstants *constants)
{
    const WireParameters *params = &stepper->params;
    PlantOutputs *outputs = &stepper->outputs;
    double xi_p = stepper->xi_P;
    double xi_m = 0.5 * stepper->xi_MF;
    double xi_f = constants->xi_F_min + xi_m;
    outputs->R = params->R_P * xi_p + params->R_M * xi_m + params->R_F * xi_f;
    outputs->T = stepper->temperature;
    if (!constants->has_lengths) {
        outputs->x = params->l_P * xi_p + params->l_M * xi_m + params->l_F * xi_f;
    } else {   /* the strain terms: stress law and thermal expansion */
        outputs->x = wire_length(stepper->temperature, xi_p, xi_m, xi_f, constants->length_M,
                                 constants->length_F, params);
    }
    outputs->xi_P = xi_p;
    outputs->xi_M = xi_m;
    outputs->xi_F = xi_f;
    outputs->P = stepper->power;
    outputs->heating = stepper->direction == HEATING;
}

static void check_validity(PlantStepper *stepper, double before, double load_before)
{
    validity_warning(&stepper->params, stepper->temperature, before, stepper->load, load_before,
                     stepper->warning, sizeof stepper->warning);
}

/* Add the data-range warning the first time T or the load is outside the range the wire's
 * data covered (once per stepper; plant.py's _check_data_range). */
static void check_data_range(PlantStepper *stepper)
{
    if (data_range_warning(&stepper->params, stepper->temperature, stepper->load, "T",
                           stepper->warning, sizeof stepper->warning)) {
        stepper->data_unwarned = 0;
    }
}

int plant_stepper_init(PlantStepper *stepper, const WireParameters *params,
                       const double *T_start, const char *mode, double load,
                       SmaMessage *message)
{
    HysteresisMode checked_mode;
    BranchCache branches;
    BranchConstants constants;
    ReversalPoint *reversals;
    double temperature;
    if (require_mode(mode, "hysteresis mode", &checked_mode, message)) {
        return 1;
    }
    branch_cache_init(&branches);
    temperature = params->T_room;
    if (T_start != NULL) {
        if (require_temperature("T_start", *T_start, message)) {
            return 1;
        }
        temperature = *T_start;
    }
    if (require_nonnegative("load", load, message)
            || branch_cache_get(&branches, params, load, HEATING, &constants, message)) {
        return 1;
    }
    reversals = malloc(((size_t)params->memory_depth + 1) * sizeof *reversals);
    if (reversals == NULL) {
        return sma_message_set(message, "out of memory for a reversal stack of %d points",
                               params->memory_depth);
    }
    stepper->params = *params;
    stepper->mode = checked_mode;
    stepper->continuous = checked_mode == HYSTERESIS_CONTINUOUS;
    stepper->branches = branches;
    stepper->has_decay = 0;
    stepper->decay_step = stepper->decay = 0.0;
    stepper->temperature = temperature;
    stepper->direction = HEATING;
    stepper->reversals = reversals;
    stepper->reversal_count = 0;
    stepper->branch_valid = 0;
    stepper->branch_load = 0.0;
    stepper->branch_direction = 0;
    memset(&stepper->branch, 0, sizeof stepper->branch);
    stepper->load = load;
    stepper->power = 0.0;
    branch_fractions(stepper->temperature, &constants, &stepper->xi_MF, &stepper->xi_P);
    evaluate(stepper, &constants);
    stepper->warning[0] = '\0';
    stepper->data_unwarned = params->data_range;
    check_validity(stepper, -HUGE_VAL, -HUGE_VAL);
    if (stepper->data_unwarned) {
        check_data_range(stepper);
    }
    return 0;
}

int plant_stepper_step(PlantStepper *stepper, double power, double load, double step_size,
                       SmaMessage *message)
{
    const WireParameters *params = &stepper->params;
    BranchConstants constants;
    double before, after, xi_mf, xi_p, load_before;
    int direction;
    if (fast_finite("P_in", power, message)) {
        return 1;
    }
    if (!(power > 0.0)) {
        power = 0.0;
    }
    if (fast_nonnegative("load", load, message) || fast_positive("step_size", step_size, message)) {
        return 1;
    }
    if (!stepper->has_decay || step_size != stepper->decay_step) {
        stepper->decay_step = step_size;
        stepper->decay = step_decay(step_size, params->tau_th);
        stepper->has_decay = 1;
    }
    before = stepper->temperature;
    after = thermal_step(before, power, params->T_room, params->K_th, stepper->decay);
    if (!(-HUGE_VAL < after && after < HUGE_VAL)) {
        return sma_message_set(message, "P_in = %.17g W over %.17g s would take the wire "
                               "temperature out of the floating-point range", power, step_size);
    }
    direction = after > before ? HEATING : (after < before ? COOLING : stepper->direction);
    if (branch_cache_get(&stepper->branches, params, load, direction, &constants, message)) {
        return 1;
    }
    if (stepper->continuous) {
        ReversalPoint *points = stepper->reversals;
        int changed = direction != stepper->direction;
        if (changed) {
            push_reversal(points, &stepper->reversal_count, before, stepper->xi_MF,
                          (size_t)params->memory_depth);
        }
        if (stepper->reversal_count >= 2
                && wipe_out(points, &stepper->reversal_count, after, direction)) {
            changed = 1;
        }
        if (stepper->reversal_count == 0) {
            branch_fractions(after, &constants, &xi_mf, &xi_p);
        } else {
            /* Python rebuilds the branch when the constants object changes; the cache gives
             * one object per (load, direction), so that is when either changes. */
            if (changed || !stepper->branch_valid || load != stepper->branch_load
                    || direction != stepper->branch_direction) {
                stepper->branch = branch_of(points, stepper->reversal_count, &constants,
                                            direction);
                stepper->branch_valid = 1;
                stepper->branch_load = load;
                stepper->branch_direction = direction;
            }
            fractions_on_branch(after, &constants, direction, &stepper->branch, &xi_mf, &xi_p);
        }
    } else {
        branch_fractions(after, &constants, &xi_mf, &xi_p);
    }
    load_before = stepper->load;
    stepper->temperature = after;
    stepper->direction = direction;
    stepper->load = load;
    stepper->power = power;
    stepper->xi_MF = xi_mf;
    stepper->xi_P = xi_p;
    evaluate(stepper, &constants);
    stepper->warning[0] = '\0';
    if (after > params->T_max || load > params->load_max) {
        check_validity(stepper, before, load_before);
    }
    if (stepper->data_unwarned) {
        check_data_range(stepper);
    }
    return 0;
}

void plant_stepper_free(PlantStepper *stepper)
{
    free(stepper->reversals);
    stepper->reversals = NULL;
    stepper->reversal_count = 0;
}

size_t plant_stepper_state_size(const PlantStepper *stepper)
{
    return PLANT_STATE_FIXED + 2 * stepper->reversal_count;
}

void plant_stepper_state_write(const PlantStepper *stepper, double *out)
{
    size_t index;
    out[0] = stepper->temperature;
    out[1] = stepper->direction;
    out[2] = stepper->load;
    out[3] = stepper->xi_MF;
    out[4] = stepper->xi_P;
    out[5] = stepper->power;
    out[6] = (double)stepper->reversal_count;
    for (index = 0; index < stepper->reversal_count; index++) {
        out[PLANT_STATE_FIXED + 2 * index] = stepper->reversals[index].temperature;
        out[PLANT_STATE_FIXED + 2 * index + 1] = stepper->reversals[index].xi_MF;
    }
}

int plant_stepper_state_read(PlantStepper *stepper, const double *in, size_t count,
                             SmaMessage *message)
{
    const WireParameters *params = &stepper->params;
    BranchConstants constants;
    SmaMessage reason;
    double total, points;
    size_t depth = (size_t)params->memory_depth, n;
    int direction;
    if (count < PLANT_STATE_FIXED) {
        return read_entries(count, PLANT_STATE_FIXED, "plant state", message);
    }
    if (read_temperature(in[0], "temperature", params->T_max, 0, NULL, message)
            || read_direction(in[1], "direction", &direction, message)
            || read_number(in[2], "load", 0.0, HUGE_VAL, "kg", message)) {
        return 1;
    }
    if (branch_cache_get(&stepper->branches, params, in[2], direction, &constants, &reason)) {
        return sma_message_set(message, "state entry load: %s", reason.text);
    }
    total = constants.M;
    if (read_number(in[3], "xi_MF", 0.0, total, "", message)
            || read_number(in[4], "xi_P", 0.0, total, "", message)) {
        return 1;
    }
    if (fabs(in[3] + in[4] - total) > 1e-9) {
        return sma_message_set(message, "state entries xi_MF = %.17g and xi_P = %.17g must add up "
                               "to M = 1 - xi_Fmin(load) = %.17g", in[3], in[4], total);
    }
    if (read_number(in[5], "power", 0.0, HUGE_VAL, "W", message)) {
        return 1;
    }
    points = in[6];
    if (!(points >= 0.0 && points <= (double)depth && points == floor(points))) {
        return sma_message_set(message, "reversals must be a list of at most %lu [T, xi_MF] pairs, "
                               "got a count of %.17g", (unsigned long)depth, points);
    }
    n = (size_t)points;
    if (count != PLANT_STATE_FIXED + 2 * n) {
        return sma_message_set(message, "reversals: the plant state holds %lu numbers, not "
                               "%d + 2 x %lu for its %lu reversal points", (unsigned long)count,
                               PLANT_STATE_FIXED, (unsigned long)n, (unsigned long)n);
    }
    if (read_points(in + PLANT_STATE_FIXED, n, depth, "reversals", NULL, message)) {
        return 1;
    }
    read_points(in + PLANT_STATE_FIXED, n, depth, "reversals", stepper->reversals, NULL);
    stepper->reversal_count = n;
    stepper->temperature = in[0];
    stepper->direction = direction;
    stepper->load = in[2];
    stepper->xi_MF = in[3];
    stepper->xi_P = in[4];
    stepper->power = in[5];
    stepper->branch_valid = 0;
    evaluate(stepper, &constants);
    return 0;
}
