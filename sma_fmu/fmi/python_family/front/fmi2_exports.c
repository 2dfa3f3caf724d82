/*
 * fmi2_exports.c - the 34 FMI 2.0 co-simulation functions of the sma-fmu C front (the Python family's binary).
 *
 * Each call is forwarded to pythonfmu's binary (backend.c), with these changes:
 *  - fmi2Instantiate checks instanceName, fmuType, fmuGUID (against modelDescription.xml)
 *    and fmuResourceLocation (resource_uri.c) and returns NULL with a logged message
 *    instead of crashing; it loads libpython when the process has none.
 *  - a call returns the worst status the slave logged during it (host_log.c): that is how
 *    the Python slave, which cannot return a status from most callbacks, reports fmi2Error
 *    for an illegal call or fmi2Warning for a left validity range.
 *  - strings (fmi2SetString, instance name, categories) must be non-NULL UTF-8, arrays
 *    non-NULL: else fmi2Error before pythonfmu turns them into Python objects.
 *  - fmi2Terminated: pythonfmu reports it true for good after any fmi2Discard. Here a
 *    discarded step means "not done, the master may fix its inputs and retry"; only the
 *    very same step (t, h) discarded twice in a row reports fmi2Terminated, so masters that
 *    retry unchanged (fmpy, fmusim) stop instead of looping.
 *  - saved states are wrapped (FrontState, fmi2_states.c) so unknown or freed pointers give fmi2Error;
 *    serialized states carry a checked header (c_common/state_frame.c).
 *  - after fmi2Fatal (pythonfmu released its Python objects) every call is refused and
 *    fmi2FreeInstance leaks pythonfmu's instance instead of freeing it twice.
 *  - a pointer that is not a live instance (freed, or never one) is refused, not used
 *    (instances.c): fmi2FreeInstance twice or any call after it is logged, never a crash.
 *  - fmi2Instantiate takes pythonfmu's entry for the resources folder off sys.path again.
 *  - in stepComplete, fmi2Set/GetReal, Integer and Boolean are served from values the front
 *    holds (fast_path.c): Python runs in fmi2DoStep, which hands the inputs over and takes
 *    the outputs back. fmi2DoStep itself makes the guard's model-free checks in C and calls
 *    the slave's step directly (not through pythonfmu) when they pass. Every other call, and every call the front would refuse, goes to the
 *    slave (after the pending inputs), so the guard's rules and messages stay as they are.
 */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "front.h"


/* What `sma-fmu check` finds in a binary that is this front (sma_fmu/fmi/packaging/front_build.py). */
/* the words "native front" predate "native" meaning the C family; kept: sma-fmu check finds
   every front, old or new, by them (packaging/platforms.py, FRONT_MARKER) */
EXPORT const char sma_fmu_front[] = "sma-fmu native front";

EXPORT const char* fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char* fmi2GetVersion(void) { return "2.0"; }

EXPORT fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                                     fmi2String fmuResourceLocation,
                                     const fmi2CallbackFunctions* functions, fmi2Boolean visible,
                                     fmi2Boolean loggingOn)
{
    Instance* in = (Instance*)calloc(1, sizeof *in);
    if (!in) return NULL;
    in->host_logger = functions ? functions->logger : NULL;
    in->host_environment = functions ? functions->componentEnvironment : NULL;
    in->log_all = loggingOn ? 1 : 0;
    in->log_problems = 1;
    int good_name = instanceName && *instanceName && valid_utf8(instanceName);
    in->name = strdup(good_name ? instanceName : "?");
    char err[8192];
    char* path = NULL;
    char* uri = NULL;
    int plain_path = 0;
    if (!in->name) goto fail;
    if (!good_name) {
        host_log(in, fmi2Error, NULL, "fmi2Instantiate: instanceName must be a non-empty UTF-8 string");
        goto fail;
    }
    if (fmuType != fmi2CoSimulation) {
        host_log(in, fmi2Error, NULL, "fmi2Instantiate: this FMU supports co-simulation only");
        goto fail;
    }
    if (!fmuGUID || !valid_utf8(fmuGUID)) {
        host_log(in, fmi2Error, NULL, "fmi2Instantiate: fmuGUID is NULL or not UTF-8");
        goto fail;
    }
    uri = resource_uri_for_pythonfmu(fmuResourceLocation, err, sizeof err, &path, &plain_path);
    if (!uri) {
        host_logf(in, fmi2Error, "fmi2Instantiate: %s", err);
        goto fail;
    }
    if (plain_path)
        host_logf(in, fmi2Warning, "fmi2Instantiate: fmuResourceLocation '%s' is a path, not a file: "
                  "URI (FMI 2.0 section 2.1.6); accepted", fmuResourceLocation);
    if (!guid_matches(path, fmuGUID, err, sizeof err)) {
        host_logf(in, fmi2Error, "fmi2Instantiate: %s", err);
        goto fail;
    }
    if (!load_backend()) {
        host_logf(in, fmi2Error, "fmi2Instantiate: %s", load_error);
        goto fail;
    }
    host_logf(in, fmi2OK, "sma-fmu front: %s", load_info);
    in->callbacks.logger = front_logger;
    in->callbacks.allocateMemory = functions ? functions->allocateMemory : NULL;
    in->callbacks.freeMemory = functions ? functions->freeMemory : NULL;
    in->callbacks.componentEnvironment = in;
    in->backend = instantiate_backend(instanceName, fmuType, fmuGUID, uri, &in->callbacks, visible);
    if (!in->backend) {
        host_log(in, fmi2Error, NULL, "fmi2Instantiate: the Python slave could not be created (see above)");
        goto fail;
    }
    keep_thread_state();
    forget_resources(path);
    fast_attach(in);
    if (!register_instance(in)) {
        host_log(in, fmi2Error, NULL, "fmi2Instantiate: out of memory");
        backend.FreeInstance(in->backend);
        goto fail;
    }
    free(uri);
    free(path);
    return in;
fail:
    free(uri);
    free(path);
    free_instance_memory(in);
    return NULL;
}

EXPORT void fmi2FreeInstance(fmi2Component c)
{
    if (!c) return;
    Instance* in = live_instance(c, "fmi2FreeInstance");
    if (!in || !retire_instance(in)) return; /* refused (logged), or freed meanwhile */
    if (!in->dead) { /* after fmi2Fatal pythonfmu has released it: leak, don't crash */
        keep_thread_state();
        while (in->states) drop_state(in, in->states);
        backend.FreeInstance(in->backend);
    }
    in->backend = NULL;
    free_categories(in); /* the rest is released when it leaves the freed instances kept */
}

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                                      const fmi2String categories[])
{
    ENTER(SetDebugLogging);
    if (!set_debug_logging(in, loggingOn, nCategories, categories))
        return refuse(in, fmi2Error, "fmi2SetDebugLogging", "categories[] is NULL or holds a NULL "
                      "or non-UTF-8 category");
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined,
                                      fmi2Real tolerance, fmi2Real startTime,
                                      fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    ENTER(SetupExperiment);
    FORWARD(in, 0, backend.SetupExperiment(in->backend, toleranceDefined, tolerance, startTime,
                                           stopTimeDefined, stopTime));
    return status;
}

EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    ENTER(EnterInitializationMode);
    FORWARD(in, 0, backend.EnterInitializationMode(in->backend));
    if (status <= fmi2Warning) in->stepped = in->terminated = in->have_discard = 0;
    return status;
}

EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    ENTER(ExitInitializationMode);
    FORWARD(in, 1, backend.ExitInitializationMode(in->backend));
    return status;
}

EXPORT fmi2Status fmi2Terminate(fmi2Component c)
{
    ENTER(Terminate);
    FORWARD(in, 0, backend.Terminate(in->backend));
    return status;
}

EXPORT fmi2Status fmi2Reset(fmi2Component c)
{
    ENTER(Reset);
    FORWARD(in, 0, backend.Reset(in->backend));
    if (!in->dead) fast_attach(in); /* pythonfmu made a new slave: its table and buffer */
    if (status <= fmi2Warning) in->stepped = in->terminated = in->have_discard = 0;
    return status;
}

/* served: fast_get / fast_set with kind 'R', 'I' or 'B'; none: (0) */
#define FORWARD_ARRAY(name, T, served)                                                          \
    EXPORT fmi2Status fmi2##name(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,    \
                                 T value[])                                                     \
    {                                                                                           \
        ENTER(name);                                                                            \
        if (nvr == 0) return fmi2OK;                                                            \
        if (!vr || !value) return refuse(in, fmi2Error, "fmi2" #name, "vr[] or value[] is NULL"); \
        if (nvr > 1000000) return refuse(in, fmi2Error, "fmi2" #name, "nvr is implausibly large"); \
        if (served) return fmi2OK;                                                              \
        FORWARD(in, 0, backend.name(in->backend, vr, nvr, value));                              \
        return status;                                                                          \
    }
FORWARD_ARRAY(GetReal, fmi2Real, fast_ready(in) && fast_get(in, 'R', vr, nvr, value))
FORWARD_ARRAY(GetInteger, fmi2Integer, fast_ready(in) && fast_get(in, 'I', vr, nvr, value))
FORWARD_ARRAY(GetBoolean, fmi2Boolean, fast_ready(in) && fast_get(in, 'B', vr, nvr, value))
FORWARD_ARRAY(GetString, fmi2String, 0)
FORWARD_ARRAY(SetReal, const fmi2Real, fast_ready(in) && fast_set(in, 'R', vr, nvr, value))
FORWARD_ARRAY(SetInteger, const fmi2Integer, fast_ready(in) && fast_set(in, 'I', vr, nvr, value))
FORWARD_ARRAY(SetBoolean, const fmi2Boolean, fast_ready(in) && fast_set(in, 'B', vr, nvr, value))

EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                const fmi2String value[])
{
    ENTER(SetString);
    if (nvr == 0) return fmi2OK;
    if (!vr || !value) return refuse(in, fmi2Error, "fmi2SetString", "vr[] or value[] is NULL");
    if (nvr > 1000000) return refuse(in, fmi2Error, "fmi2SetString", "nvr is implausibly large");
    for (size_t i = 0; i < nvr; ++i) {
        if (!value[i] || !valid_utf8(value[i])) {
            host_logf(in, fmi2Error, "fmi2SetString: value[%zu] for value reference %u is %s; "
                      "nothing was set", i, vr[i], value[i] ? "not UTF-8" : "NULL");
            return fmi2Error;
        }
    }
    FORWARD(in, 0, backend.SetString(in->backend, vr, nvr, value));
    return status;
}

EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[],
                                               size_t nu, const fmi2ValueReference z[], size_t nz,
                                               const fmi2Real dz[], fmi2Real du[])
{
    ENTER(GetDirectionalDerivative);
    (void)u; (void)nu; (void)z; (void)nz; (void)dz; (void)du;
    return refuse(in, fmi2Error, "fmi2GetDirectionalDerivative", "not supported by this FMU "
                  "(providesDirectionalDerivative is false)");
}

EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                              size_t nvr, const fmi2Integer order[],
                                              const fmi2Real value[])
{
    ENTER(SetRealInputDerivatives);
    (void)vr; (void)nvr; (void)order; (void)value;
    return refuse(in, fmi2Error, "fmi2SetRealInputDerivatives", "not supported by this FMU "
                  "(canInterpolateInputs is false)");
}

EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                               size_t nvr, const fmi2Integer order[],
                                               fmi2Real value[])
{
    ENTER(GetRealOutputDerivatives);
    (void)vr; (void)nvr; (void)order; (void)value;
    return refuse(in, fmi2Error, "fmi2GetRealOutputDerivatives", "not supported by this FMU "
                  "(maxOutputDerivativeOrder is 0)");
}

EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                             fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    ENTER(DoStep);
    int direct = fast_step(in, currentCommunicationPoint, communicationStepSize);
    fmi2Status status;
    if (direct >= 0) {
        status = (fmi2Status)direct;
    } else {
        fast_before_step(in); /* the slave takes the pending inputs and writes the outputs */
        status = finish(in, backend.DoStep(in->backend, currentCommunicationPoint,
                                           communicationStepSize, noSetFMUStatePriorToCurrentPoint));
        fast_after_step(in);
        in->own_last_time = 0; /* pythonfmu's fmi2LastSuccessfulTime is current again */
    }
    if (status > fmi2Discard) return status; /* refused (illegal call): nothing was stepped */
    in->stepped = 1;
    if (status != fmi2Discard) {
        in->terminated = in->have_discard = 0;
        return status;
    }
    int same_step = in->have_discard && in->discard_time == currentCommunicationPoint &&
                    in->discard_step == communicationStepSize;
    in->terminated = same_step;
    if (same_step)
        host_logf(in, fmi2Error, "fmi2DoStep(t = %.17g s, h = %.17g s) was repeated unchanged after "
                  "a discard and discarded again: reporting fmi2Terminated so the master stops",
                  currentCommunicationPoint, communicationStepSize);
    in->have_discard = 1;
    in->discard_time = currentCommunicationPoint;
    in->discard_step = communicationStepSize;
    return status;
}

EXPORT fmi2Status fmi2CancelStep(fmi2Component c)
{
    ENTER(CancelStep);
    return refuse(in, fmi2Error, "fmi2CancelStep", "illegal call: no asynchronous step is in progress");
}

#define REQUIRE_STEPPED(function)                                                               \
    if (!in->stepped)                                                                           \
        return refuse(in, fmi2Error, function, "illegal call sequence: allowed only after fmi2DoStep")

EXPORT fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status* value)
{
    ENTER(GetStatus);
    (void)s; (void)value;
    REQUIRE_STEPPED("fmi2GetStatus");
    return refuse(in, fmi2Discard, "fmi2GetStatus", "defined only while fmi2DoStep is pending, "
                  "and this FMU never returns fmi2Pending");
}

EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real* value)
{
    ENTER(GetRealStatus);
    REQUIRE_STEPPED("fmi2GetRealStatus");
    if (!value) return refuse(in, fmi2Error, "fmi2GetRealStatus", "value is NULL");
    if (s != fmi2LastSuccessfulTime)
        return refuse(in, fmi2Discard, "fmi2GetRealStatus", "only fmi2LastSuccessfulTime is defined");
    if (in->own_last_time) { /* the last step was direct: pythonfmu's value is older */
        *value = in->last_time;
        return fmi2OK;
    }
    FORWARD(in, 0, backend.GetRealStatus(in->backend, s, value));
    return status;
}

EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer* value)
{
    ENTER(GetIntegerStatus);
    (void)s; (void)value;
    REQUIRE_STEPPED("fmi2GetIntegerStatus");
    return refuse(in, fmi2Discard, "fmi2GetIntegerStatus", "no integer status is defined");
}

EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean* value)
{
    ENTER(GetBooleanStatus);
    REQUIRE_STEPPED("fmi2GetBooleanStatus");
    if (!value) return refuse(in, fmi2Error, "fmi2GetBooleanStatus", "value is NULL");
    if (s != fmi2Terminated)
        return refuse(in, fmi2Discard, "fmi2GetBooleanStatus", "only fmi2Terminated is defined");
    *value = in->terminated ? fmi2True : fmi2False;
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String* value)
{
    ENTER(GetStringStatus);
    (void)s; (void)value;
    REQUIRE_STEPPED("fmi2GetStringStatus");
    return refuse(in, fmi2Discard, "fmi2GetStringStatus", "no string status is defined");
}
