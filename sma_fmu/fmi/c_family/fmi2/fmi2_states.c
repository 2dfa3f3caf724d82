/* Saved FMU states: fmi2Get/Set/FreeFMUstate and their serialization, checked.
 *
 * A state is kept as its serialized bytes (fmi2_state_bytes.c), so restoring a state and
 * deserializing one take the same checked path. Restoring checks everything before it
 * changes anything (saved_state.py): then a new stepper is started from the saved
 * parameters and takes the saved doubles through the runtime's <x>_state_read, which
 * validates them as restore() does, and must write them back unchanged. A refused state
 * leaves the instance as it was: fmi2Error with the reason. */
#include "fp_contract.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2_layer.h"

/* A new stepper from the saved parameters, then its saved doubles (StepperSlave._set_fmu_state);
 * NULL with why set. The start's outputs go to a scratch copy: the saved ones are kept. */
static void *restored_stepper(const Instance *in, const Parsed *p, char *why, size_t size)
{
    const SmaModel *model = in->model;
    SmaMessage message;
    SmaRun run = in->run;
    SmaValue *scratch = layer_values_copy(model, p->values);
    void *stepper = calloc(1, model->stepper_size ? model->stepper_size : 1);
    double *again = (double *)malloc((p->count ? p->count : 1) * sizeof *again);
    int started = 0;
    message.text[0] = '\0';
    run.start_time = p->start_time;
    run.first_step = p->first_step;
    if (!scratch || !stepper || !again) {
        snprintf(why, size, "out of memory");
        goto fail;
    }
    if (model->start(stepper, scratch, &run, &message)) {
        snprintf(why, size, "the model could not take it back (ValueError: %s)", message.text);
        goto fail;
    }
    started = 1;
    if (model->state_read(stepper, p->doubles, p->count, &message)) {
        snprintf(why, size, "the model could not take it back (ValueError: %s)", message.text);
        goto fail;
    }
    if (model->state_size(stepper) != p->count ||
        (model->state_write(stepper, again), memcmp(again, p->doubles, p->count * sizeof *again) != 0)) {
        snprintf(why, size, "the hidden model state is corrupt (the model does not save it back unchanged)");
        goto fail;
    }
    layer_values_free(model, scratch);
    free(again);
    return stepper;
fail:
    if (started && model->free) model->free(stepper);
    layer_values_free(model, scratch);
    free(stepper);
    free(again);
    return NULL;
}

/* Restore the state in `bytes` into `in`: all or nothing; fmi2Error with the reason. The
 * bytes are a state the instance keeps (written by it, or deserialized, frame checked). */
static fmi2Status restore(Instance *in, const unsigned char *bytes, size_t size)
{
    char why[700];
    Parsed p;
    void *stepper = NULL;
    if (!layer_parse_state(in, bytes, size, 1, &p, why, sizeof why)) goto refused;
    if (p.has_stepper && !(stepper = restored_stepper(in, &p, why, sizeof why))) goto refused;
    if ((p.state == STATE_STEP_COMPLETE || p.state == STATE_TERMINATED) &&
        !layer_outputs_finite(in, p.values)) {
        snprintf(why, sizeof why, "the outputs it gives are not finite");
        if (stepper) { if (in->model->free) in->model->free(stepper); free(stepper); }
        goto refused;
    }
    layer_drop_stepper(in);
    in->stepper = stepper;
    layer_values_free(in->model, in->values);
    in->values = p.values;
    p.values = NULL;
    in->state = (LayerState)p.state;
    in->run.start_time = p.start_time;
    in->run.first_step = p.first_step;
    in->stop_time = p.stop_time;
    in->stop_defined = p.stop_defined;
    in->time = p.time;
    in->time_defined = p.time_defined;
    in->outputs_current = p.outputs_current;
    snprintf(in->initial_error, sizeof in->initial_error, "%s", p.initial_error);
    layer_parsed_free(in->model, &p);
    return fmi2OK;
refused:
    layer_parsed_free(in->model, &p);
    layer_log(in, fmi2Error, "fmi2SetFMUstate: state refused, the instance is unchanged: %s", why);
    return fmi2Error;
}

/* ---- the FMI functions ------------------------------------------------------------------- */
static SavedState *find(Instance *in, fmi2FMUstate state)
{
    SavedState *s;
    for (s = in->states; s; s = s->next)
        if ((void *)s == state) return s;
    return NULL;
}

static void drop(Instance *in, SavedState *state)
{
    SavedState **link;
    for (link = &in->states; *link; link = &(*link)->next) {
        if (*link == state) { *link = state->next; break; }
    }
    free(state->bytes);
    free(state);
}

void layer_free_states(Instance *in)
{
    while (in->states) drop(in, in->states);
}

/* Keep `bytes` in *state: the saved state already there, or a new one. */
static fmi2Status hand_out(Instance *in, const char *function, fmi2FMUstate *state,
                           unsigned char *bytes, size_t size)
{
    SavedState *saved = *state ? find(in, *state) : NULL;
    if (!saved) {
        saved = (SavedState *)calloc(1, sizeof *saved);
        if (!saved) {
            free(bytes);
            return layer_refuse(in, fmi2Error, function, "out of memory");
        }
        saved->next = in->states;
        in->states = saved;
    }
    free(saved->bytes);
    saved->bytes = bytes;
    saved->size = size;
    *state = saved;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state)
{
    unsigned char *bytes;
    size_t size = 0;
    ENTER;
    if (!state) return layer_reject(in, fmi2Error, "fmi2GetFMUstate", "FMUstate is NULL");
    if (*state && !find(in, *state))
        return layer_reject(in, fmi2Error, "fmi2GetFMUstate", "*FMUstate is neither NULL nor a "
                            "state of this instance");
    bytes = layer_serialize(in, &size);
    if (!bytes) return layer_refuse(in, fmi2Error, "fmi2GetFMUstate", "out of memory");
    return hand_out(in, "fmi2GetFMUstate", state, bytes, size);
}

FMI2_Export fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state)
{
    SavedState *saved;
    ENTER;
    saved = state ? find(in, state) : NULL;
    if (!saved)
        return layer_reject(in, fmi2Error, "fmi2SetFMUstate", "FMUstate is not a state of this "
                            "instance (NULL, freed, or another instance's)");
    return restore(in, saved->bytes, saved->size);
}

FMI2_Export fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state)
{
    SavedState *saved;
    ENTER;
    if (!state || !*state) return fmi2OK;  /* FMI 2.0: freeing NULL does nothing */
    saved = find(in, *state);
    if (!saved)
        return layer_reject(in, fmi2Error, "fmi2FreeFMUstate", "*FMUstate is not a state of this "
                            "instance (freed, or another instance's)");
    drop(in, saved);
    *state = NULL;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t *size)
{
    SavedState *saved;
    ENTER;
    saved = state ? find(in, state) : NULL;
    if (!saved || !size)
        return layer_reject(in, fmi2Error, "fmi2SerializedFMUstateSize", "FMUstate is not a state "
                            "of this instance, or size is NULL");
    *size = saved->size;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state,
                                             fmi2Byte serializedState[], size_t size)
{
    SavedState *saved;
    ENTER;
    saved = state ? find(in, state) : NULL;
    if (!saved || !serializedState)
        return layer_reject(in, fmi2Error, "fmi2SerializeFMUstate", "FMUstate is not a state of "
                            "this instance, or serializedState is NULL");
    if (size < saved->size) {
        layer_log(in, fmi2Error, "fmi2SerializeFMUstate: size %lu is less than the %lu bytes of "
                  "the state (fmi2SerializedFMUstateSize)", (unsigned long)size,
                  (unsigned long)saved->size);
        return fmi2Error;
    }
    memcpy(serializedState, saved->bytes, saved->size);
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[],
                                               size_t size, fmi2FMUstate *state)
{
    char why[700];
    unsigned char *bytes;
    Parsed p;
    ENTER;
    if (!state || (!serializedState && size))
        return layer_reject(in, fmi2Error, "fmi2DeSerializeFMUstate", "serializedState or "
                            "FMUstate is NULL");
    if (*state && !find(in, *state))
        return layer_reject(in, fmi2Error, "fmi2DeSerializeFMUstate", "*FMUstate is neither NULL "
                            "nor a state of this instance");
    if (!layer_parse_state(in, (const unsigned char *)serializedState, size, 0, &p, why,
                           sizeof why)) {
        layer_parsed_free(in->model, &p);
        layer_log(in, fmi2Error, "fmi2DeSerializeFMUstate: the bytes are refused: %s", why);
        return fmi2Error;
    }
    layer_parsed_free(in->model, &p);
    bytes = (unsigned char *)malloc(size ? size : 1);
    if (!bytes) return layer_refuse(in, fmi2Error, "fmi2DeSerializeFMUstate", "out of memory");
    memcpy(bytes, serializedState, size);
    return hand_out(in, "fmi2DeSerializeFMUstate", state, bytes, size);
}
