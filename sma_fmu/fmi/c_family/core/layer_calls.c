/* The calling sequence both fronts share: the instance's life (new, instantiate, reset,
 * free), setup, entering and leaving Initialization Mode, and the checks every call makes.
 *
 * The states, refusals and messages are the pythonfmu FMUs' (slave_support/guards.py and
 * the front in fmi/python_family/front/fmi2_exports.c); each front passes the name of its
 * own function, so a message names the function the host called:
 *  - a call in a state where it is illegal: an error, "illegal call in state '<state>'";
 *  - ExitInitializationMode with parameters the model refuses: an error naming the reason,
 *    the instance stays in Initialization Mode (fix them and call it again). */
#include "fp_contract.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "layer.h"

/* What `sma-fmu check` finds in a native binary (fmi/packaging/c_family_build.py). */
static const char NATIVE_MARKER[] = "sma-fmu native C FMU";

const char *const STATE_NAMES[STATE_COUNT] = {
    "instantiated", "Initialization Mode", "stepComplete", "terminated", "error"};

Instance *layer_instance(const void *c, const char *function)
{
    Instance *in = layer_live(c, function);
    if (!in) return NULL;
    in->worst = SMA_OK;
    return in;
}

SmaStatus layer_finish(const Instance *in, SmaStatus status)
{
    return in->worst > status ? in->worst : status;
}

int layer_allowed(Instance *in, const char *function, unsigned int mask)
{
    char why[80];
    if (mask & (1u << in->state)) return 1;
    snprintf(why, sizeof why, "illegal call in state '%s'", STATE_NAMES[in->state]);
    layer_refuse(in, SMA_ERROR, function, why);
    return 0;
}

void layer_validity(Instance *in, const char *function)
{
    const char *warning = in->model->warning && in->stepper ? in->model->warning(in->stepper) : "";
    if (warning && *warning) layer_log(in, SMA_WARNING, "%s: %s", function, warning);
}

/* What an instance holds, but not its name and struct (layer_instances.c keeps those a
 * while after FreeInstance). */
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

void layer_discard(Instance *in)
{
    if (!in) return;
    release_contents(in);
    free(in->name);
    free(in);
}

int layer_initial_state(Instance *in, char *why, size_t size)
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

Instance *layer_new(const char *prefix, const char *instance_name, LayerEmit emit,
                    void (*logger)(void), void *environment, int logging_on)
{
    int good_name = instance_name && *instance_name && layer_valid_utf8(instance_name);
    char function[32];
    Instance *in = (Instance *)calloc(1, sizeof *in);
    if (!in) return NULL;
    in->model = &SMA_MODEL;
    in->prefix = prefix;
    in->emit = emit;
    in->logger = logger;
    in->environment = environment;
    in->log_all = logging_on ? 1 : 0;
    in->log_problems = 1;
    in->name = copy_text(good_name ? instance_name : "?");
    if (!in->name) {
        free(in);
        return NULL;
    }
    in->run.model_name = in->model->name;
    in->run.instance_name = in->name;
    if (!good_name) {
        snprintf(function, sizeof function, "%sInstantiate", prefix);
        layer_reject(in, SMA_ERROR, function, "instanceName must be a non-empty UTF-8 string");
        layer_discard(in);
        return NULL;
    }
    return in;
}

/* FMI 3.0 calls fmuResourceLocation resourcePath: the shared URI reader's messages in its words. */
static void fmi3_words(char *text)
{
    static const char OLD[] = "fmuResourceLocation", NEW[] = "resourcePath";
    char *at;
    while ((at = strstr(text, OLD)) != NULL) {  /* NEW is shorter: the text only shrinks */
        memmove(at + sizeof NEW - 1, at + sizeof OLD - 1, strlen(at + sizeof OLD - 1) + 1);
        memcpy(at, NEW, sizeof NEW - 1);
    }
}

int layer_instantiate(Instance *in, const char *function, const char *token,
                      const char *token_name, const char *resource_location)
{
    char why[1200];
    int plain = 0, fmi2 = in->prefix[3] == '2';
    if (!token || !layer_valid_utf8(token)) {
        snprintf(why, sizeof why, "%s is NULL or not UTF-8", token_name);
        layer_reject(in, SMA_ERROR, function, why);
        goto fail;
    }
    in->guid = copy_text(token);
    if (!in->guid) goto fail;
    if (!layer_resource_folder(resource_location, &in->resources, &plain, why, sizeof why)) {
        if (!fmi2) fmi3_words(why);
        layer_plain(in, SMA_ERROR, "%s: %s", function, why);
        goto fail;
    }
    if (plain && fmi2)
        layer_plain(in, SMA_WARNING, "%s: fmuResourceLocation '%s' is a path, not a file: URI "
                    "(FMI 2.0 section 2.1.6); accepted", function, resource_location);
    if (!plain && !fmi2)
        layer_plain(in, SMA_WARNING, "%s: resourcePath '%s' is a URI, not a path (FMI 3.0 "
                    "section 2.3.1); accepted", function, resource_location);
    if (!layer_initial_state(in, why, sizeof why)) {
        layer_log(in, SMA_ERROR, "%s: %s", function, why);
        goto fail;
    }
    /* the host's token is its model description's: it must be the one the resources were
     * built for (the binary is the same for every wire: docs/fmus.md, "One wire") */
    if (strcmp(token, in->build_token) != 0) {
        layer_plain(in, SMA_ERROR, "%s: %s '%s' does not match the %s '%s' of this FMU's "
                    "resources folder '%s' (wire %s): the model description and the resources "
                    "are of different builds (another parameter file, version or model)",
                    function, token_name, token, fmi2 ? "guid" : "instantiationToken",
                    in->build_token, in->resources, in->wire_digest);
        goto fail;
    }
    layer_log(in, SMA_OK, "%s: %s (%s)", function, NATIVE_MARKER, in->resources);
    layer_register(in);
    return 1;
fail:
    layer_discard(in);
    return 0;
}

void layer_free(Instance *in, const char *function)
{
    (void)function;
    release_contents(in);
    layer_keep(in);
}

SmaStatus layer_setup(Instance *in, const char *function, double start_time, int stop_defined,
                      double stop_time)
{
    char a[32], b[32];
    if (!layer_allowed(in, function, IN(STATE_INSTANTIATED))) return SMA_ERROR;
    layer_repr(start_time, a);
    layer_repr(stop_time, b);
    if (!isfinite(start_time)) {
        layer_log(in, SMA_ERROR, "%s: startTime = %s s is not finite", function, a);
        return SMA_ERROR;
    }
    if (stop_defined && !(start_time <= stop_time && stop_time < HUGE_VAL)) {
        layer_log(in, SMA_ERROR, "%s: stopTime = %s s is not finite and >= startTime = %s s",
                  function, b, a);
        return SMA_ERROR;
    }
    in->run.start_time = start_time;
    in->time_defined = 1;
    in->stop_defined = stop_defined ? 1 : 0;
    in->stop_time = stop_time;
    return SMA_OK;
}

SmaStatus layer_enter_initialization(Instance *in, const char *function)
{
    if (!layer_allowed(in, function, IN(STATE_INSTANTIATED))) return SMA_ERROR;
    in->state = STATE_INITIALIZATION;
    in->outputs_current = 0;
    in->stepped = in->terminated = in->have_discard = 0;
    return SMA_OK;
}

SmaStatus layer_exit_initialization(Instance *in, const char *function, LayerState next)
{
    char why[sizeof in->initial_error];
    if (!layer_allowed(in, function, IN(STATE_INITIALIZATION))) return SMA_ERROR;
    if (layer_run_initialization(in, why, sizeof why)) {
        in->outputs_current = 1;
        memcpy(in->initial_error, why, sizeof why);
        layer_log(in, SMA_ERROR, "%s: refused, the instance stays in Initialization Mode: %s",
                  function, why);
        return SMA_ERROR;
    }
    in->state = next;
    in->time = in->run.start_time;  /* None (no check of the first step) without setup */
    layer_validity(in, function);
    return layer_finish(in, SMA_OK);
}

int layer_arrays_ok(Instance *in, const char *function, const void *vr, size_t nvr,
                    const void *value, SmaStatus *status)
{
    *status = SMA_OK;
    if (nvr == 0) return 0;
    if (!vr || !value) *status = layer_reject(in, SMA_ERROR, function, "vr[] or value[] is NULL");
    else if (nvr > 1000000) *status = layer_reject(in, SMA_ERROR, function, "nvr is implausibly large");
    else return 1;
    return 0;
}
