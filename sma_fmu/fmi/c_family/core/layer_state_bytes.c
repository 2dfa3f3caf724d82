/* Saved FMU states as bytes (fmi2_states.c keeps and restores them): the layout below,
 * written by layer_serialize and read back, every entry checked, by layer_parse_state.
 * The body goes inside the frame of c_common/state_frame.c (header with length and CRC-32),
 * which is checked first: a changed, truncated or extended state is refused whole.
 * The body (native byte order, declared by the header):
 *   "SMAFMU2S" | u32 format version (2) | u32 byte-order mark | str model name |
 *   str wire digest | str GUID | str the stepper's state format (e.g. PLANT_STATE_FORMAT) |
 *   u32 calling-sequence state | f64 start_time, stop_time, time, first_step |
 *   u8 stop_defined, time_defined, outputs_current | str initial_error |
 *   u32 variable count | each variable: f64 (Real), i32 (Integer, Boolean), str (String) |
 *   u8 has stepper | u32 count | f64 x count (the stepper's <x>_state_write layout)
 * where str = u32 length + UTF-8 bytes. Reading refuses, with the reason, bytes of another
 * model, wire (the digest of the build's parameter file: saved_state.py says the same),
 * structure (GUID: another version) or stepper format, truncated bytes, an entry out of
 * range, and anything that follows the state. */
#include "fp_contract.h"
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "layer.h"
#include "state_frame.h"  /* the frame both families put around a state */

#define MAGIC "SMAFMU2S"
#define FORMAT_VERSION 2u
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
    put_text(w, in->wire_digest);
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

unsigned char *layer_serialize(const Instance *in, size_t *size)
{
    Writer w = {NULL, STATE_FRAME_SIZE};  /* the body follows the frame's header */
    write_state(in, &w);
    w.bytes = (unsigned char *)malloc(w.size);
    if (!w.bytes) return NULL;
    *size = w.size;
    w.size = STATE_FRAME_SIZE;
    write_state(in, &w);
    if (w.size != *size) { free(w.bytes); return NULL; }
    state_frame_write(w.bytes, *size - STATE_FRAME_SIZE);
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


void layer_parsed_free(const SmaModel *model, Parsed *p)
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

/* The wire the state was saved with must be this FMU's: the same sentence as the pythonfmu
 * family's (saved_state.py), naming both digests. Beside the frame's checks, before any
 * entry is read. */
static int expect_wire(Reader *r, const char *digest)
{
    char *text = take_text(r, "the wire digest");
    int same;
    if (!text) return 0;
    same = strcmp(text, digest) == 0;
    if (!same)
        snprintf(r->why, r->why_size, "the state was saved by an FMU of another wire (%.80s); "
                 "this FMU's wire is %.80s: restore it into an FMU built from the same parameter "
                 "file", text, digest);
    free(text);
    return same;
}

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
    if (!expect_text(r, "model", model->name, "") || !expect_wire(r, in->wire_digest) ||
        !expect_text(r, "the FMU build (GUID)", model->guid, ": another version or model") ||
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


int layer_parse_state(const Instance *in, const unsigned char *bytes, size_t size, int framed,
                      Parsed *p, char *why, size_t why_size)
{
    Reader r;
    memset(p, 0, sizeof *p);
    why[0] = '\0';
    if (!framed && !state_frame_check(bytes, size, why, why_size)) return 0;
    if (size < STATE_FRAME_SIZE) return 0;  /* framed: never (the instance's own bytes) */
    r.bytes = bytes + STATE_FRAME_SIZE; r.size = size - STATE_FRAME_SIZE; r.at = 0;
    r.why = why; r.why_size = why_size;
    return parse(in, &r, p);
}
