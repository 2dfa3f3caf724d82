/* fmi3DoStep, the saved states, and the functions of what this FMU does not have: the FMI 3.0
 * front over the core's step (core/layer_step.c) and states (core/layer_states.c).
 *
 * fmi3DoStep answers as fmi2DoStep does (the same checks, discard and warning) and reports
 * through its outputs: lastSuccessfulTime is where the instance now is, terminateSimulation
 * is set when the very same step was discarded twice. With event mode used, a model with
 * events of its own (the PWM driver: its edges) asks for event handling when a step ends at
 * an event, and with early return allowed a step stops at the first event inside it. */
#include "fp_contract.h"
#include <stdio.h>

#include "fmi3_layer.h"

/* The model's next event after `time` [s], or a value <= time when it has none. */
static double next_event(const Instance *in, double time)
{
    if (!in->model->next_event || !in->stepper) return time - 1.0;
    return in->model->next_event(in->stepper, in->values, time);
}

FMI3_Export fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint,
                                  fmi3Float64 communicationStepSize,
                                  fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                  fmi3Boolean *eventHandlingNeeded,
                                  fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn,
                                  fmi3Float64 *lastSuccessfulTime)
{
    double t = currentCommunicationPoint, h = communicationStepSize, event = t - 1.0;
    int early = 0;
    SmaStatus status;
    ENTER;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (!eventHandlingNeeded || !terminateSimulation || !earlyReturn || !lastSuccessfulTime)
        DONE(layer_reject(in, SMA_ERROR, "fmi3DoStep", "eventHandlingNeeded, terminateSimulation, "
                          "earlyReturn or lastSuccessfulTime is NULL"));
    *eventHandlingNeeded = *terminateSimulation = *earlyReturn = fmi3False;
    *lastSuccessfulTime = in->time_defined ? in->time : in->run.start_time;
    if (in->event_mode)
        DONE(layer_reject(in, SMA_ERROR, "fmi3DoStep", "illegal call in Event Mode (call "
                          "fmi3EnterStepMode first)"));
    if (in->event_mode_used && in->state == STATE_STEP_COMPLETE && h > 0.0) {
        event = next_event(in, t);
        /* with early return allowed, the step ends at the model's next event inside it */
        early = in->early_return && event > t && event < t + h - 1e-9 * h;
    }
    status = layer_step(in, "fmi3DoStep", t, early ? event - t : h);
    *terminateSimulation = status == SMA_DISCARD && in->terminated ? fmi3True : fmi3False;
    *lastSuccessfulTime = in->time_defined ? in->time : in->run.start_time;
    if (status <= SMA_WARNING && in->event_mode_used) {
        double end = *lastSuccessfulTime;
        *earlyReturn = early ? fmi3True : fmi3False;
        *eventHandlingNeeded = early || (event > t && (event <= end + 1e-9 * h)) ? fmi3True
                                                                                  : fmi3False;
    }
    DONE(status);
}

FMI3_Export fmi3Status fmi3EnterStepMode(fmi3Instance instance)
{
    ENTER;
    if (!in->event_mode)
        DONE(layer_reject(in, SMA_ERROR, "fmi3EnterStepMode", "illegal call: the instance is "
                          "not in Event Mode"));
    in->event_mode = 0;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance,
                                                fmi3Boolean *discreteStatesNeedUpdate,
                                                fmi3Boolean *terminateSimulation,
                                                fmi3Boolean *nominalsOfContinuousStatesChanged,
                                                fmi3Boolean *valuesOfContinuousStatesChanged,
                                                fmi3Boolean *nextEventTimeDefined,
                                                fmi3Float64 *nextEventTime)
{
    double time, event;
    ENTER;
    if (!in->event_mode)
        DONE(layer_reject(in, SMA_ERROR, "fmi3UpdateDiscreteStates", "illegal call: the "
                          "instance is not in Event Mode"));
    if (!discreteStatesNeedUpdate || !terminateSimulation || !nominalsOfContinuousStatesChanged ||
        !valuesOfContinuousStatesChanged || !nextEventTimeDefined || !nextEventTime)
        DONE(layer_reject(in, SMA_ERROR, "fmi3UpdateDiscreteStates", "an output argument is NULL"));
    /* the models' discrete states change only in a step: nothing to iterate here */
    *discreteStatesNeedUpdate = *terminateSimulation = fmi3False;
    *nominalsOfContinuousStatesChanged = *valuesOfContinuousStatesChanged = fmi3False;
    time = in->time_defined ? in->time : in->run.start_time;
    event = next_event(in, time);
    *nextEventTimeDefined = event > time ? fmi3True : fmi3False;
    *nextEventTime = event > time ? event : 0.0;
    return fmi3OK;
}

/* ---- saved states ------------------------------------------------------------------------ */
FMI3_Export fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    ENTER;
    DONE(layer_get_state(in, "fmi3GetFMUState", FMUState));
}

FMI3_Export fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState)
{
    ENTER;
    DONE(layer_set_state(in, "fmi3SetFMUState", FMUState));
}

FMI3_Export fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    ENTER;
    DONE(layer_free_state(in, "fmi3FreeFMUState", FMUState));
}

FMI3_Export fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState,
                                                  size_t *size)
{
    SavedState *saved;
    ENTER;
    saved = FMUState ? layer_find_state(in, FMUState) : NULL;
    if (!saved || !size)
        DONE(layer_reject(in, SMA_ERROR, "fmi3SerializedFMUStateSize", "FMUState is not a state "
                          "of this instance, or size is NULL"));
    *size = saved->size;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState,
                                             fmi3Byte serializedState[], size_t size)
{
    ENTER;
    DONE(layer_serialize_state(in, "fmi3SerializeFMUState", FMUState, serializedState, size));
}

FMI3_Export fmi3Status fmi3DeserializeFMUState(fmi3Instance instance,
                                               const fmi3Byte serializedState[], size_t size,
                                               fmi3FMUState *FMUState)
{
    ENTER;
    DONE(layer_deserialize_state(in, "fmi3DeserializeFMUState", serializedState, size, FMUState));
}
