/* SmaActuator: the SMA wire plant (thermal model + resistance hysteresis), native.
 *
 * A thin adapter over runtime/plant (PlantStepper), as the slave beside it (sma_actuator.py) is:
 * doStep(t, h) holds P_in and load over the step (P_in <= 0 is applied as 0 W); the outputs
 * are then the state at t + h. After initialization the outputs reflect T_start and the
 * load. Invalid parameters refuse fmi2ExitInitializationMode; hysteresis_mode is an Integer
 * (1 = continuous, 2 = switch); a step leaving the validity range logs fmi2Warning.
 *
 * FMI 3.0 arrays (get_array): the reversal stack, oldest first, as two arrays of
 * memory_depth values, 0: the reversal temperatures T_i [degC], 1: their xi_MF_i [1];
 * the elements past the stack's reversal_count entries are NaN. */
#include "fp_contract.h"
#include <math.h>

#include "plant.h"
#include "sma_choices.h"
#include "sma_wire.h"
#include "SmaActuator_variables.h"

static void publish(SmaValue *values, const PlantOutputs *outputs)
{
    values[VAR_R].real = outputs->R;
    values[VAR_T].real = outputs->T;
    values[VAR_x].real = outputs->x;
    values[VAR_xi_P].real = outputs->xi_P;
    values[VAR_xi_M].real = outputs->xi_M;
    values[VAR_xi_F].real = outputs->xi_F;
    values[VAR_P].real = outputs->P;
    values[VAR_heating].integer = outputs->heating ? 1 : 0;
}

static int start(void *stepper, SmaValue *values, SmaRun *run, SmaMessage *message)
{
    PlantStepper *plant = (PlantStepper *)stepper;
    WireParameters params;
    const char *mode;
    if (sma_wire_parameters(&SMA_MODEL, values, run, &params, message) ||
        choice_name("hysteresis_mode", values[VAR_hysteresis_mode].integer, &mode, message) ||
        plant_stepper_init(plant, &params, &values[VAR_T_start].real, mode,
                           values[VAR_load].real, message))
        return 1;
    publish(values, &plant->outputs);
    return 0;
}

static int step(void *stepper, SmaValue *values, SmaRun *run, double time, double step_size,
                SmaMessage *message)
{
    PlantStepper *plant = (PlantStepper *)stepper;
    (void)run;
    (void)time;
    if (plant_stepper_step(plant, values[VAR_P_in].real, values[VAR_load].real, step_size,
                           message))
        return 1;
    publish(values, &plant->outputs);
    return 0;
}

static void release(void *stepper) { plant_stepper_free((PlantStepper *)stepper); }

static const char *warning(const void *stepper) { return ((const PlantStepper *)stepper)->warning; }

static size_t state_size(const void *stepper)
{
    return plant_stepper_state_size((const PlantStepper *)stepper);
}

static void state_write(const void *stepper, double *out)
{
    plant_stepper_state_write((const PlantStepper *)stepper, out);
}

static int state_read(void *stepper, const double *in, size_t count, SmaMessage *message)
{
    return plant_stepper_state_read((PlantStepper *)stepper, in, count, message);
}

static int get_array(const void *stepper, const SmaValue *values, size_t array,
                     double values_out[], size_t nValues, size_t *index)
{
    const PlantStepper *plant = (const PlantStepper *)stepper;
    size_t size = (size_t)values[VAR_memory_depth].integer, i;
    if (*index > nValues || nValues - *index < size) return 1;
    for (i = 0; i < size; ++i) {
        if (i >= plant->reversal_count) values_out[*index + i] = NAN;
        else if (array == 0) values_out[*index + i] = plant->reversals[i].temperature;
        else values_out[*index + i] = plant->reversals[i].xi_MF;
    }
    *index += size;
    return 0;
}

static size_t live_count(const void *stepper)
{
    return ((const PlantStepper *)stepper)->reversal_count;
}

static void held_outputs(const void *stepper, SmaValue *values)
{
    publish(values, &((const PlantStepper *)stepper)->outputs);
}

const SmaModel SMA_MODEL = {
    MODEL_NAME, MODEL_GUID, PLANT_STATE_FORMAT, LOG_CATEGORIES, VARIABLES, VAR_COUNT,
    1, sizeof(PlantStepper), start, step, release, warning, state_size, state_write, state_read, NULL,
    2, VAR_memory_depth, get_array, live_count, held_outputs};
