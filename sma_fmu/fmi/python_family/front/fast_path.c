/*
 * fast_path.c - fmi2Set/GetReal, Integer and Boolean served from values the front holds, so
 * that Python runs only in fmi2DoStep (and in the calls that need the model).
 *
 * Right after the slave is created (fmi2Instantiate, fmi2Reset) the front asks it for its
 * variable table (fmi2GetString of FAST_DESCRIBE_VR: kind, value reference and whether it
 * may be set in stepComplete, per Real, Integer and Boolean variable) and hands it a buffer
 * of doubles (fmi2SetString of FAST_ATTACH_VR: the buffer's address). The slave's guard
 * (slave_support/fast_path.py) writes its state and every value into the buffer after each
 * call that can change them, and the outputs after each step.
 *
 * While the slave is in stepComplete (and the buffer shows that), the front serves:
 *  - fmi2Get*: the values from the buffer (every reference must be a variable of that type);
 *  - fmi2Set*: checked against the slave's table for stepComplete (inputs and tunable
 *    parameters), written into the buffer and marked pending; all or nothing.
 * Anything else, a refused call included, goes to the slave as before, so every refusal is
 * the guard's, with its message. Before such a call the pending inputs are handed over (one
 * crossing, FAST_SYNC_VR); afterwards the buffer counts as stale and is refreshed (the same
 * crossing) before the front serves a call again. fmi2DoStep hands the pending inputs over
 * and takes the outputs back in its own crossing. Initialization Mode (outputs follow the
 * inputs there), terminated and error states are never served here.
 *
 * fmi2DoStep without pythonfmu (fast_step): while the buffer is current and shows
 * stepComplete, the front makes the guard's model-free checks itself (finite t, 0 < h < inf,
 * t follows the last step up to rounding, the step's end not past stopTime: the guard's
 * _do_step, on the time and stopTime the slave writes) and, if they pass, calls the slave's
 * direct step (slave_support/direct_step.py, its address in the header) through Python's C
 * API with t, h and the pending inputs as arguments (StepCall, front.h); the step returns
 * the values it changed, which the front copies into the buffer (or writes the buffer
 * itself in the unusual cases). Messages the step queued reach the host through one more
 * crossing (fmi2GetString of FAST_LOG_VR), after which pythonfmu passes them on as it does
 * after any call. A step the checks do not pass goes through pythonfmu's DoStep, so the
 * guard refuses it with its own message. SMA_FMU_NO_DIRECT_STEP=1 switches this off.
 *
 * Buffer: FAST_HEADER doubles, then n values (slot order of the table), then n "pending"
 * flags. Header: [0] 1 if the slave is in stepComplete, [1] 1 once the slave has written
 * the buffer (the front clears it before a crossing), [2] 1 if an input is pending, [3] the
 * front's sync request, [4] 1: the next step writes every value, not only the outputs,
 * [5] the guard's stopTime (NaN: none), [6] 1 if [5] and [11] may be checked in C, [7] the
 * front's log request, [8] the direct step's address (0: none), [9] pythonfmu's log
 * queue's address, [10] the number of slots a step changes (the first ones), [11] the
 * guard's time (where the next step must start; NaN: none), next to the values: the slave
 * writes both in one pack.
 */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>

#include "front.h"

#define H_STEP_COMPLETE 0
#define H_FRESH 1
#define H_PENDING 2
#define H_SYNC 3
#define H_FULL 4
#define H_STOP 5
#define H_CHECKABLE 6
#define H_LOG 7
#define H_ENTRY 8
#define H_QUEUE 9
#define H_CHANGED 10
#define H_TIME 11
#define MAX_TABLE_VR 65536u

static int kind_index(char kind) { return kind == 'R' ? 0 : kind == 'I' ? 1 : kind == 'B' ? 2 : -1; }

void fast_free(FastPath* fast)
{
    free(fast->buffer);
    free(fast->settable);
    free(fast->kinds);
    free(fast->input_slots);
    free(fast->input_kinds);
    for (int k = 0; k < 3; ++k) free(fast->slot_of[k]);
    memset(fast, 0, sizeof *fast);
}

/* The fast path off for this instance, the buffer kept: the slave was given its address and
 * writes into it after every call it still gets (slave_support/fast_path.py: write_step),
 * so it may be freed only with the instance or when fmi2Reset replaces the slave. */
static void fast_detach(FastPath* fast)
{
    fast->attached = 0;
    fast->step = NULL;
}

/* Parses "SMAFAST1 <n> (<kind> <vr> <settable>)*n" into the tables; 1 on success. */
static int parse_table(FastPath* fast, const char* text)
{
    char* end = NULL;
    if (strncmp(text, "SMAFAST1 ", 9) != 0) return 0;
    unsigned long n = strtoul(text + 9, &end, 10);
    if (end == text + 9 || n == 0 || n > MAX_TABLE_VR) return 0;
    unsigned char* settable = (unsigned char*)calloc(n, 1);
    char* kinds = (char*)calloc(n, 1);
    unsigned* vrs = (unsigned*)calloc(n, sizeof *vrs);
    unsigned size[3] = {0, 0, 0};
    int ok = settable && kinds && vrs;
    const char* at = end;
    for (unsigned long i = 0; ok && i < n; ++i) {
        while (*at == ' ') ++at;
        kinds[i] = *at++;
        int k = kind_index(kinds[i]);
        unsigned long vr = strtoul(at, &end, 10);
        ok = k >= 0 && end != at && vr < MAX_TABLE_VR;
        at = end;
        unsigned long flag = ok ? strtoul(at, &end, 10) : 0;
        ok = ok && end != at && flag <= 1;
        at = end;
        if (!ok) break;
        vrs[i] = (unsigned)vr;
        settable[i] = (unsigned char)flag;
        if (vr + 1 > size[k]) size[k] = (unsigned)vr + 1;
    }
    for (int k = 0; ok && k < 3; ++k) {
        fast->table_size[k] = size[k];
        if (!size[k]) continue;
        fast->slot_of[k] = (int*)malloc(size[k] * sizeof(int));
        if (!fast->slot_of[k]) { ok = 0; break; }
        for (unsigned v = 0; v < size[k]; ++v) fast->slot_of[k][v] = -1;
    }
    for (unsigned long i = 0; ok && i < n; ++i) {
        int* slot = &fast->slot_of[kind_index(kinds[i])][vrs[i]];
        if (*slot >= 0) ok = 0; /* a value reference twice: leave this to the slave */
        *slot = (int)i;
    }
    if (ok) {
        fast->buffer = (double*)calloc(FAST_HEADER + 2 * n, sizeof(double));
        ok = fast->buffer != NULL;
    }
    free(vrs);
    fast->settable = settable;
    fast->kinds = kinds;
    fast->n = n;
    return ok;
}

/* The direct step, if the slave offers one: its address and the log queue's (exact in a
 * double), the inputs it takes and the number of values it returns. */
static void attach_direct_step(FastPath* fast)
{
    const double* b = fast->buffer;
    double entry = b[H_ENTRY], queue = b[H_QUEUE], changed = b[H_CHANGED];
    if (!(entry > 0.0 && entry < 9007199254740992.0 && queue > 0.0 && queue < 9007199254740992.0 &&
          changed >= 0.0 && changed <= (double)fast->n && changed == (double)(size_t)changed))
        return;
    size_t n_inputs = 0;
    for (size_t s = 0; s < fast->n; ++s) n_inputs += fast->settable[s];
    if (n_inputs > STEP_MAX_INPUTS) return;
    fast->input_slots = (int*)malloc((n_inputs ? n_inputs : 1) * sizeof(int));
    fast->input_kinds = (char*)malloc(n_inputs ? n_inputs : 1);
    if (!fast->input_slots || !fast->input_kinds) return; /* (freed with the rest) */
    fast->n_inputs = 0;
    for (size_t s = 0; s < fast->n; ++s)
        if (fast->settable[s]) {
            fast->input_slots[fast->n_inputs] = (int)s;
            fast->input_kinds[fast->n_inputs++] = fast->kinds[s];
        }
    fast->n_changed = (size_t)changed;
    fast->step = (void*)(size_t)entry;
    fast->queue = (void*)(size_t)queue;
}

/* Ask the slave for its table and give it the buffer. Without them every call goes to the
 * slave (an FMU whose slave has no fast path, or out of memory). Nothing is logged. */
void fast_attach(Instance* in)
{
    fast_free(&in->fast);
    char off[16];
    if (environment("SMA_FMU_NO_FAST_PATH", off, sizeof off) && strcmp(off, "0") != 0) return;
    fmi2Status logged = in->logged_status;
    int given = 0;
    const fmi2ValueReference describe = FAST_DESCRIBE_VR, attach = FAST_ATTACH_VR;
    fmi2String text = NULL;
    if (backend.GetString(in->backend, &describe, 1, &text) == fmi2OK && text &&
        in->logged_status == fmi2OK && parse_table(&in->fast, text)) {
        char address[64];
        snprintf(address, sizeof address, "%llu %zu",
                 (unsigned long long)(size_t)in->fast.buffer, in->fast.n);
        fmi2String value = address;
        given = 1; /* from here the slave may hold the buffer's address */
        if (backend.SetString(in->backend, &attach, 1, &value) == fmi2OK &&
            in->logged_status == fmi2OK && in->fast.buffer[H_FRESH] == 1.0) {
            in->fast.attached = 1;
            in->fast.maybe_step_complete = in->fast.buffer[H_STEP_COMPLETE] == 1.0;
            int direct = can_call_step() &&
                         !(environment("SMA_FMU_NO_DIRECT_STEP", off, sizeof off) &&
                           strcmp(off, "0") != 0);
            if (direct) attach_direct_step(&in->fast);
        }
    }
    if (!in->fast.attached) {
        if (given) fast_detach(&in->fast); /* the slave may have taken it: kept */
        else fast_free(&in->fast);
    }
    in->logged_status = logged;
}

/* One crossing: the slave takes the pending inputs and writes every value. 0 if it failed
 * (then the fast path is off for this instance, or the instance is dead). */
static int sync(Instance* in)
{
    double* b = in->fast.buffer;
    b[H_FRESH] = 0.0;
    b[H_SYNC] = 1.0;
    const fmi2ValueReference vr = FAST_SYNC_VR;
    fmi2String text = NULL;
    fmi2Status logged = in->logged_status;
    fmi2Status status = backend.GetString(in->backend, &vr, 1, &text);
    if (status == fmi2Fatal) in->dead = 1;
    int ok = status == fmi2OK && in->logged_status == fmi2OK && b[H_FRESH] == 1.0;
    in->logged_status = logged;
    if (!ok) {
        fast_detach(&in->fast); /* not freed: the slave still writes into it */
        return 0;
    }
    in->fast.stale = 0;
    in->fast.maybe_step_complete = b[H_STEP_COMPLETE] == 1.0;
    return 1;
}

int fast_ready(Instance* in)
{
    FastPath* fast = &in->fast;
    if (!fast->attached || !fast->maybe_step_complete) return 0;
    if (fast->stale && !sync(in)) return 0;
    return fast->buffer[H_STEP_COMPLETE] == 1.0;
}

void fast_flush(Instance* in)
{
    if (in->fast.attached && in->fast.buffer[H_PENDING] != 0.0) sync(in);
}

void fast_forwarded(Instance* in, int may_enter_step_complete)
{
    if (!in->fast.attached) return;
    in->fast.stale = 1;
    if (may_enter_step_complete) in->fast.maybe_step_complete = 1;
}

/* Slot of (kind, vr), or -1. */
static int slot(const FastPath* fast, int k, fmi2ValueReference vr)
{
    return vr < fast->table_size[k] ? fast->slot_of[k][vr] : -1;
}

int fast_get(Instance* in, char kind, const fmi2ValueReference vr[], size_t nvr, void* value)
{
    FastPath* fast = &in->fast;
    int k = kind_index(kind);
    for (size_t i = 0; i < nvr; ++i)
        if (slot(fast, k, vr[i]) < 0) return 0;
    const double* values = fast->buffer + FAST_HEADER;
    for (size_t i = 0; i < nvr; ++i) {
        double v = values[slot(fast, k, vr[i])];
        if (k == 0) ((fmi2Real*)value)[i] = v;
        else if (k == 1) ((fmi2Integer*)value)[i] = (fmi2Integer)v;
        else ((fmi2Boolean*)value)[i] = v != 0.0 ? fmi2True : fmi2False;
    }
    return 1;
}

int fast_set(Instance* in, char kind, const fmi2ValueReference vr[], size_t nvr, const void* value)
{
    FastPath* fast = &in->fast;
    int k = kind_index(kind);
    for (size_t i = 0; i < nvr; ++i) {
        int s = slot(fast, k, vr[i]);
        if (s < 0 || !fast->settable[s]) return 0; /* the slave refuses it, with its message */
    }
    double* values = fast->buffer + FAST_HEADER;
    double* pending = values + fast->n;
    for (size_t i = 0; i < nvr; ++i) {
        int s = slot(fast, k, vr[i]);
        if (k == 0) values[s] = ((const fmi2Real*)value)[i];
        else if (k == 1) values[s] = (double)((const fmi2Integer*)value)[i];
        else values[s] = ((const fmi2Boolean*)value)[i] ? 1.0 : 0.0;
        pending[s] = 1.0;
    }
    fast->buffer[H_PENDING] = 1.0;
    return 1;
}

void fast_before_step(Instance* in)
{
    if (!in->fast.attached) return;
    in->fast.buffer[H_FRESH] = 0.0;
    in->fast.buffer[H_FULL] = in->fast.stale ? 1.0 : 0.0;
}

void fast_after_step(Instance* in)
{
    if (!in->fast.attached) return;
    if (in->dead) {
        in->fast.attached = 0;
        return;
    }
    /* the slave wrote the outputs (every value if it was asked to) and its state */
    in->fast.stale = in->fast.buffer[H_FRESH] != 1.0;
    in->fast.maybe_step_complete = 1;
}

static double magnitude(double x) { return x < 0.0 ? -x : x; }

/* The guard's _close: equal up to rounding (relative 1e-9 of the larger magnitude). */
static int close_to(double a, double b, double step)
{
    double scale = magnitude(a);
    if (magnitude(b) > scale) scale = magnitude(b);
    if (step > scale) scale = step; /* Python's max(abs(a), abs(b), step) */
    return magnitude(a - b) <= 1e-9 * scale;
}

/* 1 if the guard's _do_step would pass fmi2DoStep(t, h) on to its advance(): the buffer is
 * current and shows stepComplete, t is finite, 0 < h < inf, t follows the last step and the
 * step does not pass stopTime (the same comparisons, in the same order). */
static int direct_step_allowed(const FastPath* fast, double t, double h)
{
    const double* b = fast->buffer;
    if (!fast->attached || !fast->step || fast->stale || b[H_STEP_COMPLETE] != 1.0 ||
        b[H_CHECKABLE] != 1.0)
        return 0;
    if (!(t > -HUGE_VAL && t < HUGE_VAL && h > 0.0 && h < HUGE_VAL)) return 0;
    double expected = b[H_TIME];
    if (expected == expected && t != expected && !close_to(t, expected, h)) return 0;
    double end = t + h, stop = b[H_STOP];
    if (stop == stop && end > stop && !close_to(end, stop, h)) return 0;
    return 1;
}

int fast_step(Instance* in, double t, double h)
{
    FastPath* fast = &in->fast;
    if (!direct_step_allowed(fast, t, h)) return -1;
    double* b = fast->buffer;
    double* values = b + FAST_HEADER;
    double* pending = values + fast->n;
    b[H_FRESH] = 0.0;
    b[H_FULL] = 0.0; /* not stale: the outputs are enough */
    StepCall call = {t, h, fast->n_inputs, fast->input_slots, fast->input_kinds, values,
                     b[H_PENDING] != 0.0 ? pending : NULL, values, fast->n_changed};
    long queued = 0;
    int outcome = call_step(fast->step, fast->queue, &queued, &call);
    if (call.pending) { /* handed over */
        for (size_t i = 0; i < fast->n_inputs; ++i) pending[fast->input_slots[i]] = 0.0;
        b[H_PENDING] = 0.0;
    }
    if (outcome >= 2) { /* the step returned its values (2) or something else (3: stale) */
        if (outcome == 3) b[H_STEP_COMPLETE] = 0.0;
        b[H_FRESH] = 1.0;
    }
    if (queued != 0) { /* pythonfmu passes the queued messages on after this call */
        const fmi2ValueReference vr = FAST_LOG_VR;
        fmi2String text = NULL;
        b[H_LOG] = 1.0;
        if (backend.GetString(in->backend, &vr, 1, &text) == fmi2Fatal) in->dead = 1;
        b[H_LOG] = 0.0;
    }
    fast_after_step(in);
    if (in->dead) return finish(in, fmi2Fatal);
    if (outcome < 0) /* a Python exception the step lets through (never an Exception) */
        return refuse(in, fmi2Error, "fmi2DoStep", "internal error: the slave's step raised "
                      "an exception that is not an Exception (printed on stderr)");
    int done = outcome != 0;
    in->own_last_time = 1;
    in->last_time = done ? t + h : t; /* as pythonfmu's fmi2DoStep */
    return finish(in, done ? fmi2OK : fmi2Discard);
}
