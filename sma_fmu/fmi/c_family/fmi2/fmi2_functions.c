/* The FMI 2.0 co-simulation functions of the native models: the front over the core.
 *
 * Each function looks its fmi2Component up in the core's registry of instances
 * (core/layer_instances.c) before reading through it, translates FMI 2.0's types and hands
 * the call to the core with its own name (core/layer_calls.c, layer_variables.c), so the
 * states, refusals and messages are those of the pythonfmu FMUs (slave_support/guards.py and
 * the front in fmi/python_family/front/fmi2_exports.c). The host's every-step fmi2SetReal
 * and fmi2GetReal take an inline path that builds no text. */
#include "fp_contract.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2_layer.h"

/* The core's message to the host's fmi2 logger, as a "%s" argument (never a format). */
static void emit(const Instance *in, SmaStatus status, const char *category, const char *text)
{
    fmi2CallbackLogger logger = (fmi2CallbackLogger)in->logger;
    logger(in->environment, in->name, (fmi2Status)status, category, "%s", text);
}

FMI2_Export const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
FMI2_Export const char *fmi2GetVersion(void) { return fmi2Version; }

FMI2_Export fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn,
                                           size_t nCategories, const fmi2String categories[])
{
    ENTER;
    if (!layer_set_debug_logging(in, loggingOn, nCategories, categories))
        return (fmi2Status)layer_reject(in, SMA_ERROR, "fmi2SetDebugLogging", "categories[] is NULL or holds "
                            "a NULL or non-UTF-8 category");
    return fmi2OK;
}

FMI2_Export fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType,
                                          fmi2String fmuGUID, fmi2String fmuResourceLocation,
                                          const fmi2CallbackFunctions *functions,
                                          fmi2Boolean visible, fmi2Boolean loggingOn)
{
    fmi2CallbackLogger logger = functions ? functions->logger : NULL;
    Instance *in = layer_new("fmi2", instanceName, emit, (void (*)(void))logger,
                             functions ? functions->componentEnvironment : NULL, loggingOn);
    (void)visible;
    if (!in) return NULL;
    if (fmuType != fmi2CoSimulation) {
        layer_reject(in, SMA_ERROR, "fmi2Instantiate", "this FMU supports co-simulation only");
        layer_discard(in);
        return NULL;
    }
    return layer_instantiate(in, "fmi2Instantiate", fmuGUID, "fmuGUID", fmuResourceLocation) ? in : NULL;
}

FMI2_Export void fmi2FreeInstance(fmi2Component c)
{
    Instance *in = layer_retire(c, "fmi2FreeInstance");
    if (in) layer_free(in, "fmi2FreeInstance");
}

FMI2_Export fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined,
                                           fmi2Real tolerance, fmi2Real startTime,
                                           fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    ENTER;
    (void)toleranceDefined;
    (void)tolerance;
    return (fmi2Status)layer_setup(in, "fmi2SetupExperiment", startTime, stopTimeDefined, stopTime);
}

FMI2_Export fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    ENTER;
    return (fmi2Status)layer_enter_initialization(in, "fmi2EnterInitializationMode");
}

FMI2_Export fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    ENTER;
    return (fmi2Status)layer_exit_initialization(in, "fmi2ExitInitializationMode",
                                                 STATE_STEP_COMPLETE);
}

FMI2_Export fmi2Status fmi2Terminate(fmi2Component c)
{
    ENTER;
    if (!layer_allowed(in, "fmi2Terminate", IN(STATE_STEP_COMPLETE))) return fmi2Error;
    in->state = STATE_TERMINATED;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2Reset(fmi2Component c)
{
    char why[1200];
    ENTER;
    if (!layer_initial_state(in, why, sizeof why)) {
        layer_log(in, SMA_ERROR, "fmi2Reset: %s", why);
        return fmi2Error;
    }
    return fmi2OK;
}

/* The host's every-step case of fmi2SetReal/fmi2GetReal, inline and without building any
 * text: every reference its variable's own index (pythonfmu's numbering) and Real, an input
 * to set (inputs may be set in every state that allows a set), any variable to get after
 * initialization. 0: not that case (nothing changed); the checked path then decides. */
SMA_INLINE int quick_set_real(Instance *in, const fmi2ValueReference vr[], size_t nvr,
                              const fmi2Real value[])
{
    const SmaVariable *variables = in->model->variables;
    size_t i, count = in->model->count;
    if (in->state > STATE_STEP_COMPLETE) return 0;
    for (i = 0; i < nvr; ++i)
        if (!(vr[i] < count && variables[vr[i]].vr == vr[i] && variables[vr[i]].kind == SMA_REAL &&
              variables[vr[i]].causality == SMA_INPUT))
            return 0;
    for (i = 0; i < nvr; ++i) in->values[vr[i]].real = value[i];
    if (in->state == STATE_INITIALIZATION) in->outputs_current = 0;
    return 1;
}

SMA_INLINE int quick_get_real(const Instance *in, const fmi2ValueReference vr[], size_t nvr,
                              fmi2Real value[])
{
    const SmaVariable *variables = in->model->variables;
    size_t i, count = in->model->count;
    if (in->state < STATE_STEP_COMPLETE) return 0;
    for (i = 0; i < nvr; ++i) {
        if (!(vr[i] < count && variables[vr[i]].vr == vr[i] && variables[vr[i]].kind == SMA_REAL))
            return 0;
        value[i] = in->values[vr[i]].real;
    }
    return 1;
}

#define GET_SET(name, kind, T)                                                                \
    FMI2_Export fmi2Status fmi2##name(fmi2Component c, const fmi2ValueReference vr[],         \
                                      size_t nvr, T value[])                                  \
    {                                                                                         \
        SmaStatus status;                                                                     \
        ENTER;                                                                                \
        if (vr && value && nvr > 0 && nvr <= 1000000 && QUICK_##name(in, vr, nvr, value))     \
            return fmi2OK;                                                                    \
        if (!layer_arrays_ok(in, "fmi2" #name, vr, nvr, value, &status)) return (fmi2Status)status; \
        return (fmi2Status)layer_finish(in, layer_##kind(in, "fmi2" #name, GET_SET_KIND_##name,  \
                                                         vr, nvr, value));                     \
    }
#define QUICK_GetReal quick_get_real
#define QUICK_SetReal quick_set_real
#define QUICK_NONE(in, vr, nvr, value) 0
#define QUICK_GetInteger QUICK_NONE
#define QUICK_GetBoolean QUICK_NONE
#define QUICK_GetString QUICK_NONE
#define QUICK_SetInteger QUICK_NONE
#define QUICK_SetBoolean QUICK_NONE
#define GET_SET_KIND_GetReal SMA_REAL
#define GET_SET_KIND_GetInteger SMA_INTEGER
#define GET_SET_KIND_GetBoolean SMA_BOOLEAN
#define GET_SET_KIND_GetString SMA_STRING
#define GET_SET_KIND_SetReal SMA_REAL
#define GET_SET_KIND_SetInteger SMA_INTEGER
#define GET_SET_KIND_SetBoolean SMA_BOOLEAN
GET_SET(GetReal, get, fmi2Real)
GET_SET(GetInteger, get, fmi2Integer)
GET_SET(GetBoolean, get, fmi2Boolean)
GET_SET(GetString, get, fmi2String)
GET_SET(SetReal, set, const fmi2Real)
GET_SET(SetInteger, set, const fmi2Integer)
GET_SET(SetBoolean, set, const fmi2Boolean)

FMI2_Export fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                     const fmi2String value[])
{
    SmaStatus status;
    size_t i;
    ENTER;
    if (!layer_arrays_ok(in, "fmi2SetString", vr, nvr, value, &status)) return (fmi2Status)status;
    for (i = 0; i < nvr; ++i) {
        if (!value[i] || !layer_valid_utf8(value[i])) {
            layer_plain(in, SMA_ERROR, "fmi2SetString: value[%lu] for value reference %u is %s; "
                      "nothing was set", (unsigned long)i, vr[i], value[i] ? "not UTF-8" : "NULL");
            return fmi2Error;
        }
    }
    return (fmi2Status)layer_finish(in, layer_set(in, "fmi2SetString", SMA_STRING, vr, nvr, value));
}
