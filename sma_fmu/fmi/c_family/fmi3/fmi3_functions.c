/* The FMI 3.0 co-simulation functions of the native models: the calling sequence.
 *
 * A thin front over the core (core/layer_calls.c): it translates FMI 3.0's types and names
 * its own functions, and the core answers as it answers FMI 2.0 (the pythonfmu FMUs' states,
 * refusals and messages). FMI 3.0's differences:
 *  - fmi3InstantiateCoSimulation takes the instantiation token and a resource path (a
 *    file: URI is accepted with a warning); Model Exchange and Scheduled Execution give
 *    NULL;
 *  - Event Mode (eventModeUsed): entered after initialization and by fmi3EnterEventMode,
 *    left by fmi3EnterStepMode; there fmi3UpdateDiscreteStates reports no discrete change
 *    and the next event time of a model that has events (the PWM driver's edges), inputs
 *    may be set and outputs read, and fmi3DoStep is refused (fmi3_step.c);
 *  - fmi3EnterInitializationMode carries fmi2SetupExperiment's start and stop times;
 *  - Configuration Mode, where the plant's structural parameter is set (fmi3_structural.c);
 *  - the messages go to the logger as text (FMI 3.0 passes no format). */
#include "fp_contract.h"
#include <stdio.h>
#include <string.h>

#include "fmi3_layer.h"

/* The core's message to the host's fmi3 logger. */
static void emit(const Instance *in, SmaStatus status, const char *category, const char *text)
{
    fmi3LogMessageCallback logger = (fmi3LogMessageCallback)in->logger;
    if (logger) logger(in->environment, (fmi3Status)status, category, text);
}

FMI3_Export const char *fmi3GetVersion(void) { return fmi3Version; }

FMI3_Export fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn,
                                           size_t nCategories, const fmi3String categories[])
{
    ENTER;
    if (!layer_set_debug_logging(in, loggingOn, nCategories, categories))
        DONE(layer_reject(in, SMA_ERROR, "fmi3SetDebugLogging", "categories[] is NULL or holds "
                          "a NULL or non-UTF-8 category"));
    return fmi3OK;
}

/* An interface type this FMU does not have: NULL, and why to the host's logger. */
static fmi3Instance unsupported(const char *function, fmi3InstanceEnvironment environment,
                                fmi3LogMessageCallback logger)
{
    char text[200];
    snprintf(text, sizeof text, "%s: %s is a co-simulation FMU only", function, SMA_MODEL.name);
    if (logger) logger(environment, fmi3Error, "logStatusError", text);
    return NULL;
}

FMI3_Export fmi3Instance fmi3InstantiateModelExchange(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage)
{
    (void)instanceName; (void)instantiationToken; (void)resourcePath; (void)visible;
    (void)loggingOn;
    return unsupported("fmi3InstantiateModelExchange", instanceEnvironment, logMessage);
}

FMI3_Export fmi3Instance fmi3InstantiateScheduledExecution(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
    fmi3LockPreemptionCallback lockPreemption, fmi3UnlockPreemptionCallback unlockPreemption)
{
    (void)instanceName; (void)instantiationToken; (void)resourcePath; (void)visible;
    (void)loggingOn; (void)clockUpdate; (void)lockPreemption; (void)unlockPreemption;
    return unsupported("fmi3InstantiateScheduledExecution", instanceEnvironment, logMessage);
}

FMI3_Export fmi3Instance fmi3InstantiateCoSimulation(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
    fmi3Boolean earlyReturnAllowed, const fmi3ValueReference requiredIntermediateVariables[],
    size_t nRequiredIntermediateVariables, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage, fmi3IntermediateUpdateCallback intermediateUpdate)
{
    const char *function = "fmi3InstantiateCoSimulation";
    Instance *in = layer_new("fmi3", instanceName, emit, (void (*)(void))logMessage,
                             instanceEnvironment, loggingOn);
    (void)visible; (void)requiredIntermediateVariables;
    (void)intermediateUpdate;
    if (!in) return NULL;
    if (nRequiredIntermediateVariables > 0) {
        layer_reject(in, SMA_ERROR, function, "requiredIntermediateVariables: this FMU provides "
                     "no intermediate update (providesIntermediateUpdate is false)");
        layer_discard(in);
        return NULL;
    }
    in->event_mode_used = eventModeUsed ? 1 : 0;
    in->early_return = earlyReturnAllowed ? 1 : 0;
    return layer_instantiate(in, function, instantiationToken, "instantiationToken", resourcePath)
               ? in : NULL;
}

FMI3_Export void fmi3FreeInstance(fmi3Instance instance)
{
    Instance *in = layer_retire(instance, "fmi3FreeInstance");
    if (in) layer_free(in, "fmi3FreeInstance");
}

FMI3_Export fmi3Status fmi3EnterInitializationMode(fmi3Instance instance,
                                                   fmi3Boolean toleranceDefined,
                                                   fmi3Float64 tolerance, fmi3Float64 startTime,
                                                   fmi3Boolean stopTimeDefined,
                                                   fmi3Float64 stopTime)
{
    const char *function = "fmi3EnterInitializationMode";
    SmaStatus status;
    ENTER;
    (void)toleranceDefined;
    (void)tolerance;
    if (in->configuration_mode)
        DONE(layer_refuse(in, SMA_ERROR, function, "illegal call in Configuration Mode; "
                          "fmi3ExitConfigurationMode first"));
    status = layer_setup(in, function, startTime, stopTimeDefined, stopTime);
    if (status != SMA_OK) DONE(status);
    DONE(layer_enter_initialization(in, function));
}

FMI3_Export fmi3Status fmi3ExitInitializationMode(fmi3Instance instance)
{
    SmaStatus status;
    ENTER;
    status = layer_exit_initialization(in, "fmi3ExitInitializationMode", STATE_STEP_COMPLETE);
    if (status <= SMA_WARNING) in->event_mode = in->event_mode_used;
    DONE(status);
}

FMI3_Export fmi3Status fmi3EnterEventMode(fmi3Instance instance)
{
    ENTER;
    if (!in->event_mode_used)
        DONE(layer_reject(in, SMA_ERROR, "fmi3EnterEventMode", "illegal call: the instance was "
                          "made with eventModeUsed = false"));
    if (!layer_allowed(in, "fmi3EnterEventMode", IN(STATE_STEP_COMPLETE))) return fmi3Error;
    in->event_mode = 1;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3Terminate(fmi3Instance instance)
{
    ENTER;
    if (!layer_allowed(in, "fmi3Terminate", IN(STATE_STEP_COMPLETE))) return fmi3Error;
    in->state = STATE_TERMINATED;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3Reset(fmi3Instance instance)
{
    char why[1200];
    ENTER;
    in->event_mode = in->configuration_mode = 0;
    if (!layer_initial_state(in, why, sizeof why)) {
        layer_log(in, SMA_ERROR, "fmi3Reset: %s", why);
        return fmi3Error;
    }
    return fmi3OK;
}
