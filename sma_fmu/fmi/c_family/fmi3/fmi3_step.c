/* fmi3DoStep, the saved states, and the functions of what this FMU does not have: the FMI 3.0
 * front over the core's step (core/layer_step.c) and states (core/layer_states.c).
 *
 * fmi3DoStep answers as fmi2DoStep does (the same checks, discard and warning) and reports
 * through its outputs: lastSuccessfulTime is where the instance now is, terminateSimulation
 * is set when the very same step was discarded twice; these FMUs neither need event handling
 * nor return early. */
#include "fp_contract.h"
#include <stdio.h>

#include "fmi3_layer.h"

FMI3_Export fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint,
                                  fmi3Float64 communicationStepSize,
                                  fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                  fmi3Boolean *eventHandlingNeeded,
                                  fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn,
                                  fmi3Float64 *lastSuccessfulTime)
{
    SmaStatus status;
    ENTER;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (!eventHandlingNeeded || !terminateSimulation || !earlyReturn || !lastSuccessfulTime)
        DONE(layer_reject(in, SMA_ERROR, "fmi3DoStep", "eventHandlingNeeded, terminateSimulation, "
                          "earlyReturn or lastSuccessfulTime is NULL"));
    status = layer_step(in, "fmi3DoStep", currentCommunicationPoint, communicationStepSize);
    *eventHandlingNeeded = fmi3False;
    *earlyReturn = fmi3False;
    *terminateSimulation = status == SMA_DISCARD && in->terminated ? fmi3True : fmi3False;
    *lastSuccessfulTime = in->time_defined ? in->time : in->run.start_time;
    DONE(status);
}

FMI3_Export fmi3Status fmi3EnterStepMode(fmi3Instance instance)
{
    ENTER;
    DONE(layer_reject(in, SMA_ERROR, "fmi3EnterStepMode", "illegal call: this FMU declares no "
                      "event mode, so it is never in Event Mode"));
}

FMI3_Export fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance,
                                                fmi3Boolean *discreteStatesNeedUpdate,
                                                fmi3Boolean *terminateSimulation,
                                                fmi3Boolean *nominalsOfContinuousStatesChanged,
                                                fmi3Boolean *valuesOfContinuousStatesChanged,
                                                fmi3Boolean *nextEventTimeDefined,
                                                fmi3Float64 *nextEventTime)
{
    ENTER;
    (void)discreteStatesNeedUpdate; (void)terminateSimulation;
    (void)nominalsOfContinuousStatesChanged; (void)valuesOfContinuousStatesChanged;
    (void)nextEventTimeDefined; (void)nextEventTime;
    DONE(layer_reject(in, SMA_ERROR, "fmi3UpdateDiscreteStates", "illegal call: this FMU "
                      "declares no event mode, so it is never in Event Mode"));
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
