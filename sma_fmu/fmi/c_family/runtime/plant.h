/* Stateful plant: thermal model + resistance hysteresis of one wire (spec sections 4, 6, 9,
 * 11); runtime/plant.py.
 *
 * plant_stepper_step advances from t_k to t_k + h with the power and the load held and
 * evaluates the outputs at the end of the step. Direction = sgn(T+ - T) (kept when T+ = T).
 * Mode "continuous": reversal stack with return-point memory (minor_loops); mode "switch":
 * the major branch of the direction. A power <= 0 W is applied as 0 W. `warning` is set
 * (non-empty) for the one step, or the start, in which T rises above validity.T_max or the
 * load above load_max, and for the first one in which T or the load lies outside the range
 * the wire's data covered (validity.T_data_min ...: once per stepper).
 *
 * Saved state (plant_stepper_state_write/read), PLANT_STATE_FIXED + 2 n doubles:
 *   [0] temperature [degC]  [1] direction (+1/-1)  [2] load [kg]  [3] xi_MF [1]  [4] xi_P [1]
 *   [5] power [W]  [6] n, the number of reversal points  [7 + 2i] T_i [degC]
 *   [8 + 2i] xi_MF_i [1] (i = 0 the oldest); Python's state() dict without its "format"
 *   entry (PLANT_STATE_FORMAT, which the FMI layer's header carries). */
#ifndef SMA_PLANT_H
#define SMA_PLANT_H

#include <stddef.h>

#include "checks.h"
#include "constant_load.h"
#include "minor_loops.h"
#include "parameters.h"
#include "sma_message.h"

#define PLANT_STATE_FORMAT "sma-fmu plant state 2: reversal stack"
#define PLANT_STATE_FIXED 7

/* Plant outputs: R [ohm], T [degC], x [m], xi_P, xi_M, xi_F [1], P = max(0, P_in) over the
 * last step [W] (0 before the first step), heating = 1 while dT/dt > 0 (last sign kept). */
typedef struct PlantOutputs {
    double R, T, x, xi_P, xi_M, xi_F, P;
    int heating;
} PlantOutputs;

typedef struct PlantStepper {
    WireParameters params;           /* a copy */
    HysteresisMode mode;
    int continuous;
    BranchCache branches;
    int has_decay;                   /* the decay cache: exp(-decay_step / tau_th) */
    double decay_step, decay;
    double temperature;              /* [degC] */
    int direction;                   /* +1 heating, -1 cooling */
    ReversalPoint *reversals;        /* heap, room for memory_depth + 1 points */
    size_t reversal_count;
    Branch branch;                   /* the branch of the top point ... */
    int branch_valid;                /* ... valid for branch_load, branch_direction */
    double branch_load;
    int branch_direction;
    double load;                     /* [kg] */
    double power;                    /* [W] */
    double xi_MF, xi_P;              /* [1] */
    PlantOutputs outputs;
    int data_unwarned;               /* the data-range warning is still to come */
    char warning[512];               /* "" = None */
} PlantStepper;

/* PlantStepper(params, T_start, mode, load): T_start NULL = params->T_room; mode "continuous"
 * or "switch". Returns 0, or 1 with the message (nothing allocated). */
int plant_stepper_init(PlantStepper *stepper, const WireParameters *params,
                       const double *T_start, const char *mode, double load,
                       SmaMessage *message);
/* One step of step_size [s] with power [W] and load [kg] held; the outputs are in
 * stepper->outputs. Refused inputs change nothing. */
int plant_stepper_step(PlantStepper *stepper, double power, double load, double step_size,
                       SmaMessage *message);
void plant_stepper_free(PlantStepper *stepper);

size_t plant_stepper_state_size(const PlantStepper *stepper);
void plant_stepper_state_write(const PlantStepper *stepper, double *out);
/* Validate every entry as PlantStepper.restore does, then take the state whole (and
 * re-evaluate the outputs); a refused state changes nothing. */
int plant_stepper_state_read(PlantStepper *stepper, const double *in, size_t count,
                             SmaMessage *message);

#endif
