/* The FMI 2.0 co-simulation functions of the native models: the calling sequence.
 *
 * The states, refusals and messages are the pythonfmu FMUs' (slave_support/guards.py and
 * the front in fmi/python_family/front/fmi2_exports.c), so the two families answer every call alike:
 *  - a call in a state where it is illegal: fmi2Error, "illegal call in state '<state>'";
 *  - fmi2ExitInitializationMode with parameters the model refuses: fmi2Error naming the
 *    reason, the instance stays in Initialization Mode (fix them and call it again);
 *  - fmi2DoStep with a bad t or h, or not following the last step: fmi2Error, nothing done;
 *    an input the model refuses: fmi2Discard naming the input and value (never fmi2Fatal);
 *    the instance stays in stepComplete, so the master may fix its inputs and retry; the
 *    very same step discarded twice in a row reports fmi2Terminated;
 *  - a step that leaves the model's validity range: fmi2Warning with the model's warning
 *    (once per excursion: the runtime says when).
 * Every call looks its fmi2Component up in the registry of instances (fmi2_instances.c)
 * before reading through it: a pointer fmi2FreeInstance freed, or one fmi2Instantiate never
 * returned, gives fmi2Error (fmi2FreeInstance: nothing) and one line on stderr, as the
 * front does. A freed instance's struct stays allocated for a while (the last 1024 freed),
 * so its address is not reused by a new instance that a stale pointer would then reach. */
#include "fp_contract.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2_layer.h"

/* What `sma-fmu check` finds in a native binary (fmi/packaging/c_family_build.py). */
static const char NATIVE_MARKER[] = "sma-fmu native C FMU";

const char *const STATE_NAMES[STATE_COUNT] = {
    "instantiated", "Initialization Mode", "stepComplete", "terminated", "error"};

Instance *layer_instance(fmi2Component c, const char *function)
{
    Instance *in = layer_live(c, function);
    if (!in) return NULL;
    in->worst = fmi2OK;
    return in;
}

fmi2Status layer_finish(const Instance *in, fmi2Status status)
{
    return in->worst > status ? in->worst : status;
}

int layer_allowed(Instance *in, const char *function, unsigned int mask)
{
    char why[80];
    if (mask & (1u << in->state)) return 1;
    snprintf(why, sizeof why, "illegal call in state '%s'", STATE_NAMES[in->state]);
    layer_refuse(in, fmi2Error, function, why);
    return 0;
}
void layer_validity(Instance *in, const char *function)
{
    const char *warning = in->model->warning && in->stepper ? in->model->warning(in->stepper) : "";
    if (warning && *warning) layer_log(in, fmi2Warning, "%s: %s", function, warning);
}

FMI2_Export const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
FMI2_Export const char *fmi2GetVersion(void) { return fmi2Version; }

FMI2_Export fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn,
                                           size_t nCategories, const fmi2String categories[])
{
    ENTER;
    if (!layer_set_debug_logging(in, loggingOn, nCategories, categories))
        return layer_reject(in, fmi2Error, "fmi2SetDebugLogging", "categories[] is NULL or holds "
                            "a NULL or non-UTF-8 category");
    return fmi2OK;
}

/* What an instance holds, but not its name and struct (fmi2_instances.c keeps those a while
 * after fmi2FreeInstance). */
static void release_contents(Instance *in)
{
    layer_free_states(in);
    layer_drop_stepper(in);
    layer_values_free(in->model, in->values);
    free(in->real_outputs);
    free(in->categories);
    free(in->resources);
    free(in->guid);
    free(in->wire_defaults);
    in->wire_defaults = NULL;
    in->run.wire_defaults = NULL;
    in->run.wire_count = 0;
    in->values = NULL;
    in->real_outputs = NULL;
    in->categories = in->resources = in->guid = NULL;
}

static void free_instance(Instance *in)  /* one fmi2Instantiate refused: never registered */
{
    if (!in) return;
    release_contents(in);
    free(in->name);
    free(in);
}

/* Back to the state of a new instance (fmi2Instantiate, fmi2Reset): 0 with `why` if the
 * packed start values cannot be read. */
static int initial_state(Instance *in, char *why, size_t size)
{
    layer_drop_stepper(in);
    layer_values_free(in->model, in->values);
    in->values = NULL;
    in->state = STATE_INSTANTIATED;
    in->run.start_time = 0.0;
    in->run.first_step = 0.0;
    in->stop_defined = in->time_defined = 0;
    in->outputs_current = 0;
    in->initial_error[0] = '\0';
    in->stepped = in->terminated = in->have_discard = 0;
    if (!layer_values_init(in)) {
        snprintf(why, size, "out of memory");
        return 0;
    }
    return !layer_build_starts(in, why, size) && !layer_packed_start_values(in, why, size);
}

static char *copy_text(const char *text)
{
    char *copy = (char *)malloc(strlen(text) + 1);
    if (copy) strcpy(copy, text);
    return copy;
}

FMI2_Export fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType,
                                          fmi2String fmuGUID, fmi2String fmuResourceLocation,
                                          const fmi2CallbackFunctions *functions,
                                          fmi2Boolean visible, fmi2Boolean loggingOn)
{
    char why[1200];
    int plain = 0;
    int good_name = instanceName && *instanceName && layer_valid_utf8(instanceName);
    Instance *in = (Instance *)calloc(1, sizeof *in);
    (void)visible;
    if (!in) return NULL;
    in->model = &SMA_MODEL;
    in->logger = functions ? functions->logger : NULL;
    in->environment = functions ? functions->componentEnvironment : NULL;
    in->log_all = loggingOn ? 1 : 0;
    in->log_problems = 1;
    in->name = copy_text(good_name ? instanceName : "?");
    if (!in->name) goto fail;
    in->run.model_name = in->model->name;
    in->run.instance_name = in->name;
    if (!good_name) {
        layer_reject(in, fmi2Error, "fmi2Instantiate", "instanceName must be a non-empty UTF-8 string");
        goto fail;
    }
    if (fmuType != fmi2CoSimulation) {
        layer_reject(in, fmi2Error, "fmi2Instantiate", "this FMU supports co-simulation only");
        goto fail;
    }
    if (!fmuGUID || !layer_valid_utf8(fmuGUID)) {
        layer_reject(in, fmi2Error, "fmi2Instantiate", "fmuGUID is NULL or not UTF-8");
        goto fail;
    }
    if (strcmp(fmuGUID, in->model->guid) != 0) {
        layer_plain(in, fmi2Error, "fmi2Instantiate: fmuGUID '%s' does not match the guid '%s' of "
                  "this FMU", fmuGUID, in->model->guid);
        goto fail;
    }
    in->guid = copy_text(fmuGUID);
    if (!in->guid) goto fail;
    if (!layer_resource_folder(fmuResourceLocation, &in->resources, &plain, why, sizeof why)) {
        layer_plain(in, fmi2Error, "fmi2Instantiate: %s", why);
        goto fail;
    }
    if (plain)
        layer_plain(in, fmi2Warning, "fmi2Instantiate: fmuResourceLocation '%s' is a path, not a "
                  "file: URI (FMI 2.0 section 2.1.6); accepted", fmuResourceLocation);
    if (!initial_state(in, why, sizeof why)) {
        layer_log(in, fmi2Error, "fmi2Instantiate: %s", why);
        goto fail;
    }
    layer_log(in, fmi2OK, "fmi2Instantiate: %s (%s)", NATIVE_MARKER, in->resources);
    layer_register(in);
    return in;
fail:
    free_instance(in);
    return NULL;
}

FMI2_Export void fmi2FreeInstance(fmi2Component c)
{
    Instance *in = layer_retire(c, "fmi2FreeInstance");
    if (!in) return;
    release_contents(in);
    layer_keep(in);
}

FMI2_Export fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined,
                                           fmi2Real tolerance, fmi2Real startTime,
                                           fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    const char *function = "fmi2SetupExperiment";
    char a[32], b[32];
    ENTER;
    (void)toleranceDefined;
    (void)tolerance;
    if (!layer_allowed(in, function, IN(STATE_INSTANTIATED))) return fmi2Error;
    layer_repr(startTime, a);
    layer_repr(stopTime, b);
    if (!isfinite(startTime)) {
        layer_log(in, fmi2Error, "%s: startTime = %s s is not finite", function, a);
        return fmi2Error;
    }
    if (stopTimeDefined && !(startTime <= stopTime && stopTime < HUGE_VAL)) {
        layer_log(in, fmi2Error, "%s: stopTime = %s s is not finite and >= startTime = %s s",
                  function, b, a);
        return fmi2Error;
    }
    in->run.start_time = startTime;
    in->time_defined = 1;
    in->stop_defined = stopTimeDefined ? 1 : 0;
    in->stop_time = stopTime;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    ENTER;
    if (!layer_allowed(in, "fmi2EnterInitializationMode", IN(STATE_INSTANTIATED))) return fmi2Error;
    in->state = STATE_INITIALIZATION;
    in->outputs_current = 0;
    in->stepped = in->terminated = in->have_discard = 0;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    const char *function = "fmi2ExitInitializationMode";
    char why[sizeof ((Instance *)0)->initial_error];
    ENTER;
    if (!layer_allowed(in, function, IN(STATE_INITIALIZATION))) return fmi2Error;
    if (layer_run_initialization(in, why, sizeof why)) {
        in->outputs_current = 1;
        memcpy(in->initial_error, why, sizeof why);
        layer_log(in, fmi2Error, "%s: refused, the instance stays in Initialization Mode: %s",
                  function, why);
        return fmi2Error;
    }
    in->state = STATE_STEP_COMPLETE;
    in->time = in->run.start_time;  /* None (no check of the first step) without setup */
    layer_validity(in, function);
    return layer_finish(in, fmi2OK);
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
    if (!initial_state(in, why, sizeof why)) {
        layer_log(in, fmi2Error, "fmi2Reset: %s", why);
        return fmi2Error;
    }
    return fmi2OK;
}

/* The front's argument checks of an array call; 0: refused (status in *status). */
static int arrays_ok(Instance *in, const char *function, const void *vr, size_t nvr,
                     const void *value, fmi2Status *status)
{
    *status = fmi2OK;
    if (nvr == 0) return 0;
    if (!vr || !value) *status = layer_reject(in, fmi2Error, function, "vr[] or value[] is NULL");
    else if (nvr > 1000000) *status = layer_reject(in, fmi2Error, function, "nvr is implausibly large");
    else return 1;
    return 0;
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
        fmi2Status status;                                                                    \
        ENTER;                                                                                \
        if (vr && value && nvr > 0 && nvr <= 1000000 && QUICK_##name(in, vr, nvr, value))     \
            return fmi2OK;                                                                    \
        if (!arrays_ok(in, "fmi2" #name, vr, nvr, value, &status)) return status;              \
        return layer_finish(in, layer_##kind(in, "fmi2" #name, GET_SET_KIND_##name, vr, nvr, value)); \
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
    fmi2Status status;
    size_t i;
    ENTER;
    if (!arrays_ok(in, "fmi2SetString", vr, nvr, value, &status)) return status;
    for (i = 0; i < nvr; ++i) {
        if (!value[i] || !layer_valid_utf8(value[i])) {
            layer_plain(in, fmi2Error, "fmi2SetString: value[%lu] for value reference %u is %s; "
                      "nothing was set", (unsigned long)i, vr[i], value[i] ? "not UTF-8" : "NULL");
            return fmi2Error;
        }
    }
    return layer_finish(in, layer_set(in, "fmi2SetString", SMA_STRING, vr, nvr, value));
}
