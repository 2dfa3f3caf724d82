/* Saved FMU states for both fronts: get, set, free, serialize, deserialize, checked.
 *
 * A state is kept as its serialized bytes (layer_state_bytes.c), so restoring a state and
 * deserializing one take the same checked path. Restoring checks everything before it
 * changes anything (saved_state.py), in this order:
 *   1. the frame: length and CRC-32 (c_common/state_frame.c; at deserialization);
 *   2. whose state it is: model, build (GUID), stepper format (layer_state_bytes.c's parse;
 *      a check of the wire's digest belongs beside the GUID's);
 *   3. the variables: each of its type, times finite;
 *   4. the stepper's entries: a new stepper is started from the saved parameters (which
 *      checks them as a parameter file's) and takes the saved doubles through the runtime's
 *      <x>_state_read, which checks each entry as restore() does (finite, in its physical
 *      range: runtime/state_entries.c), and must write them back unchanged;
 *   5. the outputs: those the stepper holds must be what it gives (held_outputs_agree),
 *      the others finite.
 * A refused state leaves the instance as it was: an error with the reason, which names the
 * entry. The messages name the front's function (`function`). */
#include "fp_contract.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "layer.h"

/* The saved outputs against those the restored stepper gives (a model whose stepper holds
 * its outputs: SmaModel.held_outputs, into `scratch`): 1 if every one is the same, else 0
 * with why naming the first that differs, its unit and the value the state gives. An edited
 * output is refused like an edited entry (StepperSlave._set_fmu_state does the same). */
static int held_outputs_agree(const SmaModel *model, const void *stepper, const SmaValue *saved,
                              SmaValue *scratch, char *why, size_t size)
{
    size_t i;
    if (!model->held_outputs) return 1;
    model->held_outputs(stepper, scratch);
    for (i = 0; i < model->count; ++i) {
        const SmaVariable *v = &model->variables[i];
        const char *unit = v->unit && strcmp(v->unit, "1") != 0 ? v->unit : "";  /* none for 1 */
        if (v->causality != SMA_OUTPUT || v->kind == SMA_STRING) continue;
        if (v->kind == SMA_REAL ? saved[i].real == scratch[i].real
                                : saved[i].integer == scratch[i].integer) continue;
        if (v->kind == SMA_REAL)
            snprintf(why, size, "the model could not take it back (ValueError: output %s = "
                     "%.17g%s%s is not what the saved model state gives (%.17g%s%s))", v->name,
                     saved[i].real, *unit ? " " : "", unit, scratch[i].real, *unit ? " " : "",
                     unit);
        else
            snprintf(why, size, "the model could not take it back (ValueError: output %s = %d "
                     "is not what the saved model state gives (%d))", v->name, saved[i].integer,
                     scratch[i].integer);
        return 0;
    }
    return 1;
}

/* A new stepper from the saved parameters, then its saved doubles (StepperSlave._set_fmu_state);
 * NULL with why set. The start's outputs go to a scratch copy: the saved ones are kept, and
 * must be those the restored stepper gives where it holds them (held_outputs_agree). */
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
    if (!held_outputs_agree(model, stepper, p->values, scratch, why, size)) goto fail;
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

/* Restore the state in `bytes` into `in`: all or nothing; an error with the reason. The
 * bytes are a state the instance keeps (written by it, or deserialized, frame checked). */
static SmaStatus restore(Instance *in, const char *function, const unsigned char *bytes,
                         size_t size)
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
    return SMA_OK;
refused:
    layer_parsed_free(in->model, &p);
    layer_log(in, SMA_ERROR, "%s: state refused, the instance is unchanged: %s", function, why);
    return SMA_ERROR;
}

/* ---- the states handed out -------------------------------------------------------------- */
SavedState *layer_find_state(Instance *in, const void *state)
{
    SavedState *s;
    for (s = in->states; s; s = s->next)
        if ((const void *)s == state) return s;
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
static SmaStatus hand_out(Instance *in, const char *function, void **state, unsigned char *bytes,
                          size_t size)
{
    SavedState *saved = *state ? layer_find_state(in, *state) : NULL;
    if (!saved) {
        saved = (SavedState *)calloc(1, sizeof *saved);
        if (!saved) {
            free(bytes);
            return layer_refuse(in, SMA_ERROR, function, "out of memory");
        }
        saved->next = in->states;
        in->states = saved;
    }
    free(saved->bytes);
    saved->bytes = bytes;
    saved->size = size;
    *state = saved;
    return SMA_OK;
}

SmaStatus layer_get_state(Instance *in, const char *function, void **state)
{
    unsigned char *bytes;
    size_t size = 0;
    if (!state) return layer_reject(in, SMA_ERROR, function, "FMUstate is NULL");
    if (*state && !layer_find_state(in, *state))
        return layer_reject(in, SMA_ERROR, function, "*FMUstate is neither NULL nor a state of "
                            "this instance");
    bytes = layer_serialize(in, &size);
    if (!bytes) return layer_refuse(in, SMA_ERROR, function, "out of memory");
    return hand_out(in, function, state, bytes, size);
}

SmaStatus layer_set_state(Instance *in, const char *function, const void *state)
{
    SavedState *saved = state ? layer_find_state(in, state) : NULL;
    if (!saved)
        return layer_reject(in, SMA_ERROR, function, "FMUstate is not a state of this instance "
                            "(NULL, freed, or another instance's)");
    return restore(in, function, saved->bytes, saved->size);
}

SmaStatus layer_free_state(Instance *in, const char *function, void **state)
{
    SavedState *saved;
    if (!state || !*state) return SMA_OK;  /* freeing NULL does nothing */
    saved = layer_find_state(in, *state);
    if (!saved)
        return layer_reject(in, SMA_ERROR, function, "*FMUstate is not a state of this instance "
                            "(freed, or another instance's)");
    drop(in, saved);
    *state = NULL;
    return SMA_OK;
}

SmaStatus layer_serialize_state(Instance *in, const char *function, const void *state,
                                unsigned char bytes[], size_t size)
{
    SavedState *saved = state ? layer_find_state(in, state) : NULL;
    if (!saved || !bytes)
        return layer_reject(in, SMA_ERROR, function, "FMUstate is not a state of this instance, "
                            "or serializedState is NULL");
    if (size < saved->size) {
        layer_log(in, SMA_ERROR, "%s: size %lu is less than the %lu bytes of the state (%s)",
                  function, (unsigned long)size, (unsigned long)saved->size,
                  in->prefix[3] == '3' ? "fmi3SerializedFMUStateSize" : "fmi2SerializedFMUstateSize");
        return SMA_ERROR;
    }
    memcpy(bytes, saved->bytes, saved->size);
    return SMA_OK;
}

SmaStatus layer_deserialize_state(Instance *in, const char *function, const unsigned char bytes[],
                                  size_t size, void **state)
{
    char why[700];
    unsigned char *copy;
    Parsed p;
    if (!state || (!bytes && size))
        return layer_reject(in, SMA_ERROR, function, "serializedState or FMUstate is NULL");
    if (*state && !layer_find_state(in, *state))
        return layer_reject(in, SMA_ERROR, function, "*FMUstate is neither NULL nor a state of "
                            "this instance");
    if (!layer_parse_state(in, bytes, size, 0, &p, why, sizeof why)) {
        layer_parsed_free(in->model, &p);
        layer_log(in, SMA_ERROR, "%s: the bytes are refused: %s", function, why);
        return SMA_ERROR;
    }
    layer_parsed_free(in->model, &p);
    copy = (unsigned char *)malloc(size ? size : 1);
    if (!copy) return layer_refuse(in, SMA_ERROR, function, "out of memory");
    memcpy(copy, bytes, size);
    return hand_out(in, function, state, copy, size);
}
