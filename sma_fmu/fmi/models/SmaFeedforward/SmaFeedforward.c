/* SmaFeedforward: the feedforward hysteresis compensator, native.
 *
 * A thin adapter over runtime/feedforward (FeedforwardStepper), as
 * the slave beside it (sma_feedforward.py) is: the temperature-sensing inverse of the wire model
 * followed by the phase-lag filter. A sampled block: doStep(t_k, h) samples R_ref and load
 * as set before the call and its outputs then hold u_ff,k for that step. After
 * initialization the outputs are those of the first sample (filter in steady state).
 * Invalid parameters refuse fmi2ExitInitializationMode; inverse is an Integer
 * (1 = major, 2 = minor-loop), shaping too (1 = none, 2 = reachable), power_cap [W] the
 * driver's P_max (0: no limit), anticipation [s] the lead at the reference's lower turn
 * (0: none). */
#include "fp_contract.h"
#include "feedforward.h"
#include "checks.h"
#include "sma_choices.h"
#include "state_entries.h"
#include "sma_wire.h"
#include "SmaFeedforward_variables.h"

static void publish(SmaValue *values, const FeedforwardOutputs *outputs)
{
    values[VAR_P_ff].real = outputs->P_ff;
    values[VAR_T_ref].real = outputs->T_ref;
    values[VAR_saturated].integer = outputs->saturated ? 1 : 0;
}

static int start(void *stepper, SmaValue *values, SmaRun *run, SmaMessage *message)
{
    FeedforwardStepper *self = (FeedforwardStepper *)stepper;
    WireParameters params;
    FeedforwardOutputs outputs;
    const char *inverse, *shaping;
    double cap = values[VAR_power_cap].real;
    if (sma_wire_parameters(&SMA_MODEL, values, run, &params, message) ||
        choice_name("inverse", values[VAR_inverse].integer, &inverse, message) ||
        choice_name("shaping", values[VAR_shaping].integer, &shaping, message) ||
        (cap != cap && require_positive("power_cap", cap, message)) ||   /* NaN is not "none" */
        feedforward_stepper_init(self, &params, params.phase_lag_alpha, params.beta,
                                 params.model_load, values[VAR_adapt_to_load].integer, inverse,
                                 shaping, cap == 0.0 ? SMA_STATE_NONE : cap, message))
        return 1;
    if (feedforward_stepper_set_anticipation(self, values[VAR_anticipation].real, message)) {
        feedforward_stepper_free(self);
        return 1;
    }
    if (feedforward_stepper_initial_outputs(self, values[VAR_R_ref].real, values[VAR_load].real,
                                            &outputs, message)) {
        feedforward_stepper_free(self);
        return 1;
    }
    publish(values, &outputs);
    return 0;
}

static int step(void *stepper, SmaValue *values, SmaRun *run, double time, double step_size,
                SmaMessage *message)
{
    FeedforwardOutputs outputs;
    (void)run;
    (void)time;
    if (feedforward_stepper_step((FeedforwardStepper *)stepper, values[VAR_R_ref].real,
                                 values[VAR_load].real, step_size, &outputs, message))
        return 1;
    publish(values, &outputs);
    return 0;
}

static void release(void *stepper) { feedforward_stepper_free((FeedforwardStepper *)stepper); }

static const char *warning(const void *stepper)
{
    return ((const FeedforwardStepper *)stepper)->warning;
}

static size_t state_size(const void *stepper)
{
    return feedforward_stepper_state_size((const FeedforwardStepper *)stepper);
}

static void state_write(const void *stepper, double *out)
{
    feedforward_stepper_state_write((const FeedforwardStepper *)stepper, out);
}

static int state_read(void *stepper, const double *in, size_t count, SmaMessage *message)
{
    return feedforward_stepper_state_read((FeedforwardStepper *)stepper, in, count, message);
}

const SmaModel SMA_MODEL = {
    MODEL_NAME, MODEL_GUID, FEEDFORWARD_STATE_FORMAT, LOG_CATEGORIES, VARIABLES, VAR_COUNT,
    1, sizeof(FeedforwardStepper), start, step, release, warning, state_size, state_write,
    state_read, NULL,
    0, 0, NULL, NULL, NULL};
