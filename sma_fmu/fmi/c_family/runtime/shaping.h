/* The compensator's demand shaped into what the wire can reach (shaping "reachable");
 * runtime/shaping.py.
 *
 * A model of the wire (a PlantStepper: mode "switch" for the major inverse, "continuous" for
 * the minor-loop one) and one model-predictive step per sample: the aim is the inverse's T*
 * when it lies on d_ref's side of the model's temperature, else that temperature; the power
 * is the thermal model's one-step inverse towards it, clamped into [0, P_max]; the model
 * steps with it by the plant's rules. P_ff is that power, T_ref the model's temperature. */
#ifndef SMA_SHAPING_H
#define SMA_SHAPING_H

#include "parameters.h"
#include "plant.h"
#include "sma_message.h"

/* SHAPINGS = ("none", "reachable"): a shaping is its index in that tuple. */
typedef enum {
    SHAPING_NONE = 0,
    SHAPING_REACHABLE = 1
} FeedforwardShaping;
#define SHAPING_COUNT 2
extern const char *const SHAPINGS[SHAPING_COUNT];

/* `shaping` ("none" or "reachable", exactly) -> *out; else refused ("shaping must be one of
 * none, reachable, got '...'"; NULL reads as Python's None). */
int require_shaping(const char *shaping, FeedforwardShaping *out, SmaMessage *message);
/* P_max [W]: NaN (Python's None: no limit) or a finite number > 0, and only with shaping
 * "reachable" ("power_cap = ... W needs shaping 'reachable', got 'none'"). */
int require_power_cap(double power_cap, FeedforwardShaping shaping, SmaMessage *message);

typedef struct ReachableShaping {
    PlantStepper model;          /* the model wire (owns its reversal stack) */
    double power_cap;            /* P_max [W]; NaN: no limit */
    int has_decay;               /* the decay cache: exp(-decay_step / tau_th) */
    double decay_step, decay;
} ReachableShaping;

/* Python's ReachableShaping(params, minor_loops, power_cap, load): the model starts at T_room
 * under `load` [kg]. Returns 0, or 1 with the message (nothing allocated). */
int reachable_shaping_init(ReachableShaping *self, const WireParameters *params,
                           int minor_loops, double power_cap, double load, SmaMessage *message);
/* (P [W], T_ref [degC], moved) for the demand T* [degC] in `direction` d_ref; the model steps
 * with `load` [kg] over `step_size` [s]. A refusal of the model's step changes nothing. */
int reachable_shaping_step(ReachableShaping *self, double demand, int direction, double load,
                           double step_size, double *power, double *temperature, int *moved,
                           SmaMessage *message);
/* 1 when `temperature` [degC] lies beyond the model's in `direction` (+1/-1). */
int reachable_shaping_ahead(const ReachableShaping *self, double temperature, int direction);
/* (P [W], T_ref [degC]) before the first step: the power that holds the model's temperature. */
void reachable_shaping_resting(const ReachableShaping *self, double *power,
                               double *temperature);
void reachable_shaping_free(ReachableShaping *self);

#endif
