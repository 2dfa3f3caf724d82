/* Saved FMU states: fmi2Get/Set/FreeFMUstate and their serialization, checked.
 *
 * A state is kept as its serialized bytes, so restoring a state and deserializing one take
 * the same checked path. The bytes (native byte order, declared by the header):
 *   "SMAFMU2S" | u32 format version | u32 byte-order mark | str model name | str GUID |
 *   str the stepper's state format (e.g. PLANT_STATE_FORMAT) |
 *   u32 calling-sequence state | f64 start_time, stop_time, time, first_step |
 *   u8 stop_defined, time_defined, outputs_current | str initial_error |
 *   u32 variable count | each variable: f64 (Real), i32 (Integer, Boolean), str (String) |
 *   u8 has stepper | u32 count | f64 x count (the stepper's <x>_state_write layout)
 * where str = u32 length + UTF-8 bytes. Restoring checks everything before it changes
 * anything (saved_state.py): the model and GUID must be this FMU's (another build carries
 * other compiled-in parameters), every entry must be in range, nothing may follow; then a
 * new stepper is started from the saved parameters and takes the saved doubles through the
 * runtime's <x>_state_read, which validates them as restore() does, and must write them back
 * unchanged. A refused state leaves the instance as it was: fmi2Error with the reason. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2_layer.h"

#define MAGIC "SMAFMU2S"
#define FORMAT_VERSION 1u
#define BYTE_ORDER_MARK 0x01020304u
#define MAX_TEXT 16000000u

/* ---- writing ------------------------------------------------------------------------------ */
typedef struct {
    unsigned char *bytes;  /* NULL: only count */
    size_t size;
} Writer;

static void put(Writer *w, const void *data, size_t n)
{
    if (w->bytes) memcpy(w->bytes + w->size, data, n);
    w->size += n;
}
static void put_u32(Writer *w, uint32_t v) { put(w, &v, sizeof v); }
static void put_f64(Writer *w, double v) { put(w, &v, sizeof v); }
static void put_u8(Writer *w, int v) { unsigned char b = (unsigned char)v; put(w, &b, 1); }
static void put_text(Writer *w, const char *text)
{
    size_t n = strlen(text);
    put_u32(w, (uint32_t)n);
    put(w, text, n);
}

static void write_state(const Instance *in, Writer *w)
{
    const SmaModel *model = in->model;
    size_t i, count = in->stepper ? model->state_size(in->stepper) : 0;
    put(w, MAGIC, 8);
    put_u32(w, FORMAT_VERSION);
    put_u32(w, BYTE_ORDER_MARK);
    put_text(w, model->name);
    put_text(w, model->guid);
    put_text(w, model->state_format);
    put_u32(w, (uint32_t)in->state);
    put_f64(w, in->run.start_time);
    put_f64(w, in->stop_defined ? in->stop_time : 0.0);
    put_f64(w, in->time_defined ? in->time : 0.0);
    put_f64(w, in->run.first_step);
    put_u8(w, in->stop_defined);
    put_u8(w, in->time_defined);
    put_u8(w, in->outputs_current);
    put_text(w, in->initial_error);
    put_u32(w, (uint32_t)model->count);
    for (i = 0; i < model->count; ++i) {
        SmaKind kind = model->variables[i].kind;
        if (kind == SMA_REAL) put_f64(w, in->values[i].real);
        else if (kind == SMA_STRING) put_text(w, in->values[i].text);
        else {
            int32_t v = in->values[i].integer;
            put(w, &v, sizeof v);
        }
    }
    put_u8(w, in->stepper != NULL);
    put_u32(w, (uint32_t)count);
    if (count) {
        double *doubles = (double *)malloc(count * sizeof *doubles);
        if (!doubles) { w->size = 0; return; }  /* caught by the caller: size 0 */
        model->state_write(in->stepper, doubles);
        put(w, doubles, count * sizeof *doubles);
        free(doubles);
    }
}

/* The serialized state of `in` (malloc'd) and its size; NULL: out of memory. */
static unsigned char *serialize(const Instance *in, size_t *size)
{
    Writer w = {NULL, 0};
    write_state(in, &w);
    w.bytes = (unsigned char *)malloc(w.size ? w.size : 1);
    if (!w.bytes) return NULL;
    *size = w.size;
    w.size = 0;
    write_state(in, &w);
    if (w.size != *size) { free(w.bytes); return NULL; }
    return w.bytes;
}

/* ---- reading ------------------------------------------------------------------------------ */
typedef struct {
    const unsigned char *bytes;
    size_t size, at;
    char *why;
    size_t why_size;
} Reader;

static int take(Reader *r, void *out, size_t n, const char *what)
{
    if (r->size - r->at < n) {
        snprintf(r->why, r->why_size, "the bytes end inside %s (truncated: %lu bytes)", what,
                 (unsigned long)r->size);
        return 0;
    }
    memcpy(out, r->bytes + r->at, n);
    r->at += n;
    return 1;
}
static int take_u32(Reader *r, uint32_t *v, const char *what) { return take(r, v, sizeof *v, what); }
static int take_f64(Reader *r, double *v, const char *what) { return take(r, v, sizeof *v, what); }
static int take_flag(Reader *r, int *v, const char *what)
{
    unsigned char b;
    if (!take(r, &b, 1, what)) return 0;
    if (b > 1) {
        snprintf(r->why, r->why_size, "%s = %u is not 0 or 1", what, (unsigned)b);
        return 0;
    }
    *v = b;
    return 1;
}
/* A malloc'd NUL-terminated copy of a str entry, or NULL (why set). */
static char *take_text(Reader *r, const char *what)
{
    uint32_t n;
    char *text;
    if (!take_u32(r, &n, what)) return NULL;
    if (n > MAX_TEXT || r->size - r->at < n) {
        snprintf(r->why, r->why_size, "the bytes end inside %s (truncated or a bad length %lu)",
                 what, (unsigned long)n);
        return NULL;
    }
    text = (char *)malloc((size_t)n + 1);
    if (!text) { snprintf(r->why, r->why_size, "out of memory"); return NULL; }
    memcpy(text, r->bytes + r->at, n);
    text[n] = '\0';
    r->at += n;
    if (strlen(text) != n || !layer_valid_utf8(text)) {
        snprintf(r->why, r->why_size, "%s is not UTF-8 text", what);
        free(text);
        return NULL;
    }
    return text;
}

/* A state read from bytes, checked but not applied. */
typedef struct {
    uint32_t state;
    double start_time, stop_time, time, first_step;
    int stop_defined, time_defined, outputs_current, has_stepper;
    char *initial_error;
    SmaValue *values;
    double *doubles;
    uint32_t count;
} Parsed;

static void parsed_free(const SmaModel *model, Parsed *p)
{
    free(p->initial_error);
    layer_values_free(model, p->values);
    free(p->doubles);
}

static int expect_text(Reader *r, const char *what, const char *expected, const char *hint)
{
    char *text = take_text(r, what);
    int same;
    if (!text) return 0;
    same = strcmp(text, expected) == 0;
    if (!same)
        snprintf(r->why, r->why_size, "the state was saved by %s '%.100s', this FMU is '%.100s'%s",
                 what, text, expected, hint);
    free(text);
    return same;
}

/* 0 with r->why set, or 1 with *p filled (free it with parsed_free). */
static int parse(const Instance *in, Reader *r, Parsed *p)
{
    const SmaModel *model = in->model;
    char magic[8];
    uint32_t version, mark, count;
    size_t i;
    memset(p, 0, sizeof *p);
    if (!take(r, magic, 8, "the header") || memcmp(magic, MAGIC, 8) != 0) {
        snprintf(r->why, r->why_size, "not a state saved by an sma-fmu native FMU (no %s header)", MAGIC);
        return 0;
    }
    if (!take_u32(r, &version, "the header") || !take_u32(r, &mark, "the header")) return 0;
    if (version != FORMAT_VERSION) {
        snprintf(r->why, r->why_size, "state format version %lu, this FMU reads version %u",
                 (unsigned long)version, FORMAT_VERSION);
        return 0;
    }
    if (mark != BYTE_ORDER_MARK) {
        snprintf(r->why, r->why_size, "the state was saved on a machine of another byte order");
        return 0;
    }
    if (!expect_text(r, "model", model->name, "") ||
        !expect_text(r, "the FMU build (GUID)", model->guid,
                     ": another parameter file, version or model") ||
        !expect_text(r, "stepper state format", model->state_format, ""))
        return 0;
    if (!take_u32(r, &p->state, "the calling-sequence state")) return 0;
    if (p->state >= STATE_COUNT) {
        snprintf(r->why, r->why_size, "calling-sequence state %lu is not one of the %d states",
                 (unsigned long)p->state, STATE_COUNT);
        return 0;
    }
    if (!take_f64(r, &p->start_time, "start_time") || !take_f64(r, &p->stop_time, "stop_time") ||
        !take_f64(r, &p->time, "time") || !take_f64(r, &p->first_step, "first_step") ||
        !take_flag(r, &p->stop_defined, "stop_defined") ||
        !take_flag(r, &p->time_defined, "time_defined") ||
        !take_flag(r, &p->outputs_current, "outputs_current"))
        return 0;
    if (!isfinite(p->start_time) || !isfinite(p->stop_time) || !isfinite(p->time) ||
        !isfinite(p->first_step) || p->first_step < 0.0) {
        snprintf(r->why, r->why_size, "a time entry (start_time, stop_time, time, first_step) "
                 "is not a finite number");
        return 0;
    }
    if (!(p->initial_error = take_text(r, "initial_error"))) return 0;
    if (strlen(p->initial_error) >= sizeof in->initial_error) {
        snprintf(r->why, r->why_size, "initial_error is too long");
        return 0;
    }
    if (!take_u32(r, &count, "the variable count")) return 0;
    if (count != model->count) {
        snprintf(r->why, r->why_size, "the state holds %lu variables, %s has %lu",
                 (unsigned long)count, model->name, (unsigned long)model->count);
        return 0;
    }
    p->values = (SmaValue *)calloc(model->count ? model->count : 1, sizeof *p->values);
    if (!p->values) { snprintf(r->why, r->why_size, "out of memory"); return 0; }
    for (i = 0; i < model->count; ++i) {  /* texts first NULL: free-able at any point */
        const SmaVariable *v = &model->variables[i];
        if (v->kind == SMA_STRING) {
            if (!(p->values[i].text = take_text(r, v->name))) return 0;
        } else if (v->kind == SMA_REAL) {
            if (!take_f64(r, &p->values[i].real, v->name)) return 0;
        } else {
            int32_t value;
            if (!take(r, &value, sizeof value, v->name)) return 0;
            if (v->kind == SMA_BOOLEAN && value != 0 && value != 1) {
                snprintf(r->why, r->why_size, "variable '%s' = %ld is not a Boolean", v->name,
                         (long)value);
                return 0;
            }
            p->values[i].integer = value;
        }
    }
    if (!take_flag(r, &p->has_stepper, "has_stepper") || !take_u32(r, &p->count, "the model state size"))
        return 0;
    if (!p->has_stepper && p->count) {
        snprintf(r->why, r->why_size, "a state without a stepper holds %lu model entries",
                 (unsigned long)p->count);
        return 0;
    }
    if ((r->size - r->at) / sizeof(double) < p->count) {
        snprintf(r->why, r->why_size, "the bytes end inside the hidden model state (truncated: "
                 "%lu entries announced)", (unsigned long)p->count);
        return 0;
    }
    if (p->count) {
        p->doubles = (double *)malloc(p->count * sizeof *p->doubles);
        if (!p->doubles) { snprintf(r->why, r->why_size, "out of memory"); return 0; }
        take(r, p->doubles, p->count * sizeof *p->doubles, "the hidden model state");
    }
    if (r->at != r->size) {
        snprintf(r->why, r->why_size, "%lu bytes follow the state", (unsigned long)(r->size - r->at));
        return 0;
    }
    if ((p->state == STATE_STEP_COMPLETE || p->state == STATE_TERMINATED) && !p->has_stepper) {
        snprintf(r->why, r->why_size, "a state in '%s' must hold the hidden model state",
                 STATE_NAMES[p->state]);
        return 0;
    }
    return 1;
}

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

/* Restore the state in `bytes` into `in`: all or nothing; fmi2Error with the reason. */
static fmi2Status restore(Instance *in, const unsigned char *bytes, size_t size)
{
    char why[700];
    Reader r;
    Parsed p;
    void *stepper = NULL;
    r.bytes = bytes; r.size = size; r.at = 0; r.why = why; r.why_size = sizeof why;
    why[0] = '\0';
    if (!parse(in, &r, &p)) goto refused;
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
    parsed_free(in->model, &p);
    return fmi2OK;
refused:
    parsed_free(in->model, &p);
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

static Instance *live(fmi2Component c)
{
    Instance *in = (Instance *)c;
    if (!in || in->magic != INSTANCE_MAGIC) return NULL;
    in->worst = fmi2OK;
    return in;
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
    Instance *in = live(c);
    if (!in) return fmi2Error;
    if (!state) return layer_reject(in, fmi2Error, "fmi2GetFMUstate", "FMUstate is NULL");
    if (*state && !find(in, *state))
        return layer_reject(in, fmi2Error, "fmi2GetFMUstate", "*FMUstate is neither NULL nor a "
                            "state of this instance");
    bytes = serialize(in, &size);
    if (!bytes) return layer_refuse(in, fmi2Error, "fmi2GetFMUstate", "out of memory");
    return hand_out(in, "fmi2GetFMUstate", state, bytes, size);
}

FMI2_Export fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state)
{
    SavedState *saved;
    Instance *in = live(c);
    if (!in) return fmi2Error;
    saved = state ? find(in, state) : NULL;
    if (!saved)
        return layer_reject(in, fmi2Error, "fmi2SetFMUstate", "FMUstate is not a state of this "
                            "instance (NULL, freed, or another instance's)");
    return restore(in, saved->bytes, saved->size);
}

FMI2_Export fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state)
{
    SavedState *saved;
    Instance *in = live(c);
    if (!in) return fmi2Error;
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
    Instance *in = live(c);
    if (!in) return fmi2Error;
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
    Instance *in = live(c);
    if (!in) return fmi2Error;
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
    Reader r;
    Parsed p;
    Instance *in = live(c);
    if (!in) return fmi2Error;
    if (!state || (!serializedState && size))
        return layer_reject(in, fmi2Error, "fmi2DeSerializeFMUstate", "serializedState or "
                            "FMUstate is NULL");
    if (*state && !find(in, *state))
        return layer_reject(in, fmi2Error, "fmi2DeSerializeFMUstate", "*FMUstate is neither NULL "
                            "nor a state of this instance");
    r.bytes = (const unsigned char *)serializedState; r.size = size; r.at = 0;
    r.why = why; r.why_size = sizeof why;
    why[0] = '\0';
    if (!parse(in, &r, &p)) {
        parsed_free(in->model, &p);
        layer_log(in, fmi2Error, "fmi2DeSerializeFMUstate: the bytes are refused: %s", why);
        return fmi2Error;
    }
    parsed_free(in->model, &p);
    bytes = (unsigned char *)malloc(size ? size : 1);
    if (!bytes) return layer_refuse(in, fmi2Error, "fmi2DeSerializeFMUstate", "out of memory");
    memcpy(bytes, serializedState, size);
    return hand_out(in, "fmi2DeSerializeFMUstate", state, bytes, size);
}
