/* The compensator's demand shaped into what the wire can reach; runtime/shaping.py (see
 * shaping.h). */
#include "fp_contract.h"
#include "shaping.h"

#include <math.h>
#include <string.h>

#include "checks.h"
#include "constants.h"
#include "state_entries.h"
#include "thermal.h"

const char *const SHAPINGS[SHAPING_COUNT] = {"none", "reachable"};

int require_shaping(const char *shaping, FeedforwardShaping *out, SmaMessage *message)
{
    int index;
    if (shaping == NULL) {
        return sma_message_set(message, "shaping must be one of none, reachable, got None");
    }
    for (index = 0; index < SHAPING_COUNT; index++) {
        if (strcmp(shaping, SHAPINGS[index]) == 0) {
            *out = (FeedforwardShaping)index;
            return 0;
        }
    }
    return sma_message_set(message, "shaping must be one of none, reachable, got '%.200s'",
                           shaping);
}

int require_power_cap(double power_cap, FeedforwardShaping shaping, SmaMessage *message)
{
    if (sma_state_is_none(power_cap)) {
        return 0;
    }
    if (require_positive("power_cap", power_cap, message)) {
        return 1;
    }
    if (shaping != SHAPING_REACHABLE) {
        return sma_message_set(message, "power_cap = %.17g W needs shaping 'reachable', got "
                               "'%s'", power_cap, SHAPINGS[shaping]);
    }
    return 0;
}

int reachable_shaping_init(ReachableShaping *self, const WireParameters *params,
                           int minor_loops, double power_cap, double load, SmaMessage *message)
{
    self->power_cap = power_cap;
    self->has_decay = 0;
    self->decay_step = self->decay = 0.0;
    return plant_stepper_init(&self->model, params, NULL, minor_loops ? "continuous" : "switch",
                              load, message);
}

int reachable_shaping_step(ReachableShaping *self, double demand, int direction, double load,
                           double step_size, double *power, double *temperature, int *moved,
                           SmaMessage *message)
{
    const WireParameters *params = &self->model.params;
    double now = self->model.temperature, chosen;
    int ahead;
    if (!self->has_decay || step_size != self->decay_step) {
        self->decay_step = step_size;
        self->decay = step_decay(step_size, params->tau_th);
        self->has_decay = 1;
    }
    ahead = reachable_shaping_ahead(self, demand, direction);
    chosen = power_to_reach(now, ahead ? demand : now, params->T_room, params->K_th, self->decay);
    *moved = !ahead && demand != now;
    if (!(chosen > 0.0)) {
        *moved = *moved || chosen < 0.0;
        chosen = 0.0;
    } else if (!sma_state_is_none(self->power_cap) && chosen > self->power_cap) {
        chosen = self->power_cap;
        *moved = 1;
    }
    if (plant_stepper_step(&self->model, chosen, load, step_size, message)) {
        return 1;
    }
    *power = chosen;
    *temperature = self->model.temperature;
    return 0;
}

int reachable_shaping_ahead(const ReachableShaping *self, double temperature, int direction)
{
    double now = self->model.temperature;
    return direction == HEATING ? temperature > now : temperature < now;
}

void reachable_shaping_resting(const ReachableShaping *self, double *power,
                               double *temperature)
{
    *temperature = self->model.temperature;
    *power = (*temperature - self->model.params.T_room) / self->model.params.K_th;
}

void reachable_shaping_free(ReachableShaping *self)
{
    plant_stepper_free(&self->model);
}
