/* Scenario signals; runtime/signals.py (see signals.h). */
#include "fp_contract.h"
#include "signals.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>


#define PI 3.14159265358979323846
#define TEXT_SIZE 512

const char *const REFERENCE_KINDS[REFERENCE_KIND_COUNT] = {
    "constant", "step", "ramp", "sine", "cosine", "table"};

/* kind -> (required keys, optional keys with defaults): only phase_deg is optional (0.0) */
static const char *const REQUIRED[REFERENCE_KIND_COUNT][5] = {
    {"value_ohm", NULL},
    {"initial_ohm", "final_ohm", "time_s", NULL},
    {"start_ohm", "end_ohm", "start_time_s", "end_time_s", NULL},
    {"offset_ohm", "amplitude_ohm", "frequency_hz", NULL},
    {"offset_ohm", "amplitude_ohm", "frequency_hz", NULL},
    {"times_s", "values_ohm", NULL}};
static const char *const OPTIONAL[REFERENCE_KIND_COUNT] = {
    NULL, NULL, NULL, "phase_deg", "phase_deg", NULL};

/* Bounded text building for messages. */
static void add(char *text, const char *more)
{
    size_t at = strlen(text), room = TEXT_SIZE - 1 - at, count = strlen(more);
    memcpy(text + at, more, count < room ? count : room);
    text[at + (count < room ? count : room)] = '\0';
}

/* repr() of a list of floats, as Python prints the converted settings. */
static void floats_repr(const double *values, size_t count, char *text)
{
    char number[40];
    size_t i;
    text[0] = '\0';
    add(text, "[");
    for (i = 0; i < count && strlen(text) < TEXT_SIZE - 1; i++) {
        json_float_repr(values[i], number, sizeof number);
        add(text, i > 0 ? ", " : "");
        add(text, number);
    }
    add(text, "]");
}

/* _number: a finite number (not a bool) as a float, else "<key> must be a finite number". */
static int number_of(const JsonValue *value, const char *key, double *out, SmaMessage *message)
{
    char repr[TEXT_SIZE];
    if (value->kind != JSON_NUMBER || !isfinite(value->number)) {
        json_value_repr(value, repr, sizeof repr);
        return sma_message_set(message, "%s must be a finite number, got %s", key, repr);
    }
    *out = value->number;
    return 0;
}

/* _numbers: a non-empty list of finite numbers (heap copy in *out). */
static int numbers_of(const JsonValue *value, const char *key, double **out, size_t *count,
                      SmaMessage *message)
{
    char repr[TEXT_SIZE];
    size_t i;
    double *numbers;
    if (value->kind != JSON_ARRAY || value->count == 0) {
        json_value_repr(value, repr, sizeof repr);
        return sma_message_set(message, "%s must be a non-empty list of numbers, got %s", key,
                               repr);
    }
    numbers = (double *)malloc(value->count * sizeof *numbers);
    if (numbers == NULL) {
        return sma_message_set(message, "%s: out of memory", key);
    }
    for (i = 0; i < value->count; i++) {
        if (number_of(&value->items[i], key, &numbers[i], message)) {
            free(numbers);
            return 1;
        }
    }
    *out = numbers;
    *count = value->count;
    return 0;
}

static int increasing(const double *times, size_t count, const char *key, SmaMessage *message)
{
    char repr[TEXT_SIZE];
    size_t i;
    for (i = 1; i < count; i++) {
        if (times[i] <= times[i - 1]) {
            floats_repr(times, count, repr);
            return sma_message_set(message, "%s must be strictly increasing, got %s", key, repr);
        }
    }
    return 0;
}

static double py_min(double a, double b)
{
    return b < a ? b : a;
}

static double py_max(double a, double b)
{
    return b > a ? b : a;
}

void reference_signal_bounds(const ReferenceSignal *s, double *lowest, double *highest)
{
    double values[2];
    const double *list = values;
    size_t count = 2, i;
    switch (s->kind) {
    case REFERENCE_CONSTANT:
        values[0] = s->value_ohm;
        count = 1;
        break;
    case REFERENCE_STEP:
        values[0] = s->initial_ohm;
        values[1] = s->final_ohm;
        break;
    case REFERENCE_RAMP:
        values[0] = s->start_ohm;
        values[1] = s->end_ohm;
        break;
    case REFERENCE_SINE:
    case REFERENCE_COSINE:
        values[0] = s->offset_ohm - fabs(s->amplitude_ohm);
        values[1] = s->offset_ohm + fabs(s->amplitude_ohm);
        break;
    default:
        list = s->values_ohm;
        count = s->count;
        break;
    }
    *lowest = *highest = list[0];
    for (i = 1; i < count; i++) {
        *lowest = py_min(*lowest, list[i]);
        *highest = py_max(*highest, list[i]);
    }
}

int reference_signal_check(const ReferenceSignal *signal, SmaMessage *message)
{
    char repr[40];
    double lowest, highest;
    reference_signal_bounds(signal, &lowest, &highest);
    if (!(lowest > 0.0)) {
        json_float_repr(lowest, repr, sizeof repr);
        return sma_message_set(message, "the reference must stay > 0 ohm, but reaches %s ohm",
                               repr);
    }
    if (!(highest <= MAX_REFERENCE_OHM)) {
        json_float_repr(highest, repr, sizeof repr);
        return sma_message_set(message, "the reference must stay <= %g ohm, but reaches %s ohm",
                               MAX_REFERENCE_OHM, repr);
    }
    return 0;
}

/* bisect.bisect_right(times, t) */
static size_t bisect_right(const double *times, size_t count, double t)
{
    size_t low = 0, high = count;
    while (low < high) {
        size_t middle = (low + high) / 2;
        if (t < times[middle]) {
            high = middle;
        } else {
            low = middle + 1;
        }
    }
    return low;
}

static double interpolate(const double *times, const double *values, size_t count, double t)
{
    size_t i;
    double share;
    if (t <= times[0]) {
        return values[0];
    }
    if (t >= times[count - 1]) {
        return values[count - 1];
    }
    i = bisect_right(times, count, t) - 1;
    if (i + 1 >= count) {
        return NAN;               /* t is NaN (Python: IndexError); never from SignalSource */
    }
    share = (t - times[i]) / (times[i + 1] - times[i]);
    return values[i] + share * (values[i + 1] - values[i]);
}

int reference_signal_value(const ReferenceSignal *s, double t, double *value,
                           SmaMessage *message)
{
    double share, angle;
    switch (s->kind) {
    case REFERENCE_CONSTANT:
        *value = s->value_ohm;
        return 0;
    case REFERENCE_STEP:
        *value = t >= s->time_s ? s->final_ohm : s->initial_ohm;
        return 0;
    case REFERENCE_RAMP:
        share = py_min(1.0, py_max(0.0, (t - s->start_time_s) / (s->end_time_s - s->start_time_s)));
        *value = s->start_ohm + share * (s->end_ohm - s->start_ohm);
        return 0;
    case REFERENCE_SINE:
    case REFERENCE_COSINE:
        /* math.radians(x) is x * (pi / 180) */
        angle = 2.0 * PI * s->frequency_hz * t + s->phase_deg * (PI / 180.0);
        if (isinf(angle)) {
            return sma_message_set(message, "math domain error");
        }
        *value = s->offset_ohm + s->amplitude_ohm
                 * (s->kind == REFERENCE_SINE ? sin(angle) : cos(angle));
        return 0;
    default:
        *value = interpolate(s->times_s, s->values_ohm, s->count, t);
        return 0;
    }
}

/* bisect.bisect_left(times, t) */
static size_t bisect_left(const double *times, size_t count, double t)
{
    size_t low = 0, high = count;
    while (low < high) {
        size_t middle = (low + high) / 2;
        if (times[middle] < t) {
            low = middle + 1;
        } else {
            high = middle;
        }
    }
    return low;
}

int reference_signal_trend(const ReferenceSignal *s, double t)
{
    double change = 0.0, angle, slope, curvature;
    size_t last, i;
    switch (s->kind) {
    case REFERENCE_STEP:
        change = t >= s->time_s ? s->final_ohm - s->initial_ohm : 0.0;
        break;
    case REFERENCE_RAMP:
        change = t > s->start_time_s ? s->end_ohm - s->start_ohm : 0.0;
        break;
    case REFERENCE_SINE:
    case REFERENCE_COSINE:
        angle = 2.0 * PI * s->frequency_hz * t + s->phase_deg * (PI / 180.0);
        slope = s->kind == REFERENCE_SINE ? cos(angle) : -sin(angle);
        curvature = s->kind == REFERENCE_SINE ? -sin(angle) : -cos(angle);
        /* at a turn (slope 0) the curvature says where it came from: a maximum, rising */
        change = s->amplitude_ohm * s->frequency_hz * (slope != 0.0 ? slope : -curvature);
        break;
    case REFERENCE_TABLE:
        last = bisect_left(s->times_s, s->count, t);   /* knots before t */
        for (i = (last < s->count - 1 ? last : s->count - 1); i-- > 0;) {
            change = s->values_ohm[i + 1] - s->values_ohm[i];
            if (change != 0.0) {
                break;
            }
        }
        break;
    default:
        break;
    }
    return change < 0.0 ? -1 : 1;
}

void reference_signal_free(ReferenceSignal *signal)
{
    free(signal->times_s);
    free(signal->values_ohm);
    signal->times_s = signal->values_ohm = NULL;
    signal->count = 0;
}

double load_profile_value(const LoadProfile *load, double t, double tolerance)
{
    size_t index = bisect_right(load->times, load->count, t + tolerance);
    return load->values[index == 0 ? load->count - 1 : index - 1];
}

void load_profile_free(LoadProfile *load)
{
    free(load->times);
    free(load->values);
    load->times = load->values = NULL;
    load->count = 0;
}

static int is_key_of(ReferenceKind kind, const JsonValue *key)
{
    int i;
    for (i = 0; REQUIRED[kind][i] != NULL; i++) {
        if (json_string_is(key, REQUIRED[kind][i])) {
            return 1;
        }
    }
    return OPTIONAL[kind] != NULL && json_string_is(key, OPTIONAL[kind]);
}

/* Python's sorted() of str keys: code point order = UTF-8 byte order. */
static int compare_keys(const void *a, const void *b)
{
    const JsonValue *x = *(const JsonValue *const *)a, *y = *(const JsonValue *const *)b;
    size_t n = x->length < y->length ? x->length : y->length;
    int c = memcmp(x->text, y->text, n);
    return c != 0 ? c : (x->length > y->length) - (x->length < y->length);
}

/* ", ".join(sorted(keys of `table` for which `known` is 0)) into text; 0 when none. */
static int unknown_keys(const JsonValue *table, int kind, char *text)
{
    const JsonValue **unknown;
    size_t count = 0, i;
    text[0] = '\0';
    unknown = (const JsonValue **)malloc((table->count + 1) * sizeof *unknown);
    if (unknown == NULL) {
        add(text, "(out of memory)");
        return 1;
    }
    for (i = 0; i < table->count; i++) {
        const JsonValue *key = &table->keys[i];
        int known = kind < 0 ? json_string_is(key, "times_s") || json_string_is(key, "values_kg")
                             : json_string_is(key, "kind") || is_key_of((ReferenceKind)kind, key);
        if (!known) {
            unknown[count++] = key;
        }
    }
    qsort(unknown, count, sizeof *unknown, compare_keys);
    for (i = 0; i < count; i++) {
        add(text, i > 0 ? ", " : "");
        add(text, unknown[i]->text);
    }
    free(unknown);
    return count > 0;
}

static double *setting(ReferenceSignal *s, const JsonValue *key)
{
    static const char *const names[] = {
        "value_ohm", "initial_ohm", "final_ohm", "time_s", "start_ohm", "end_ohm",
        "start_time_s", "end_time_s", "offset_ohm", "amplitude_ohm", "frequency_hz", "phase_deg"};
    double *fields[12];
    int i;
    fields[0] = &s->value_ohm;
    fields[1] = &s->initial_ohm;
    fields[2] = &s->final_ohm;
    fields[3] = &s->time_s;
    fields[4] = &s->start_ohm;
    fields[5] = &s->end_ohm;
    fields[6] = &s->start_time_s;
    fields[7] = &s->end_time_s;
    fields[8] = &s->offset_ohm;
    fields[9] = &s->amplitude_ohm;
    fields[10] = &s->frequency_hz;
    fields[11] = &s->phase_deg;
    for (i = 0; i < 12; i++) {
        if (json_string_is(key, names[i])) {
            return fields[i];
        }
    }
    return NULL;
}

/* The settings loop and the per-kind checks of reference_from_table. */
static int reference_settings(const JsonValue *table, ReferenceSignal *s, SmaMessage *message)
{
    char repr[TEXT_SIZE];
    size_t i, values_count = 0;
    for (i = 0; i < table->count; i++) {
        const JsonValue *key = &table->keys[i];
        if (json_string_is(key, "kind")) {
            continue;
        }
        if (json_string_is(key, "times_s")) {
            if (numbers_of(&table->items[i], "times_s", &s->times_s, &s->count, message)) {
                return 1;
            }
        } else if (json_string_is(key, "values_ohm")) {
            if (numbers_of(&table->items[i], "values_ohm", &s->values_ohm, &values_count,
                           message)) {
                return 1;
            }
        } else if (number_of(&table->items[i], key->text, setting(s, key), message)) {
            return 1;
        }
    }
    if (s->kind == REFERENCE_TABLE) {
        if (s->count != values_count) {
            return sma_message_set(message, "times_s and values_ohm must have the same length");
        }
        if (increasing(s->times_s, s->count, "times_s", message)) {
            return 1;
        }
    }
    if (s->kind == REFERENCE_RAMP && !(s->end_time_s > s->start_time_s)) {
        return sma_message_set(message, "end_time_s must be after start_time_s");
    }
    if ((s->kind == REFERENCE_SINE || s->kind == REFERENCE_COSINE) && s->frequency_hz < 0.0) {
        json_float_repr(s->frequency_hz, repr, sizeof repr);
        return sma_message_set(message, "frequency_hz must be >= 0, got %s", repr);
    }
    return reference_signal_check(s, message);
}

int reference_from_table(const JsonValue *table, ReferenceSignal *out, SmaMessage *message)
{
    static const ReferenceSignal empty;
    ReferenceSignal s = empty;
    const JsonValue *kind = json_object_get(table, "kind");
    char repr[TEXT_SIZE], keys[TEXT_SIZE], expected[TEXT_SIZE];
    int k, i;
    for (k = 0; k < REFERENCE_KIND_COUNT; k++) {
        if (kind != NULL && json_string_is(kind, REFERENCE_KINDS[k])) {
            break;
        }
    }
    if (k == REFERENCE_KIND_COUNT) {
        if (kind == NULL) {
            strcpy(repr, "None");
        } else {
            json_value_repr(kind, repr, sizeof repr);
        }
        return sma_message_set(message, "kind must be one of constant, step, ramp, sine, cosine, "
                               "table, got %s", repr);
    }
    s.kind = (ReferenceKind)k;
    json_value_repr(kind, repr, sizeof repr);
    if (unknown_keys(table, k, keys)) {
        expected[0] = '\0';
        for (i = 0; REQUIRED[k][i] != NULL; i++) {
            add(expected, i > 0 ? ", " : "");
            add(expected, REQUIRED[k][i]);
        }
        if (OPTIONAL[k] != NULL) {
            add(expected, ", ");
            add(expected, OPTIONAL[k]);
        }
        return sma_message_set(message, "unknown key(s) %s for kind %s; expected %s", keys, repr,
                               expected);
    }
    keys[0] = '\0';
    for (i = 0; REQUIRED[k][i] != NULL; i++) {
        if (json_object_get(table, REQUIRED[k][i]) == NULL) {
            add(keys, keys[0] != '\0' ? ", " : "");
            add(keys, REQUIRED[k][i]);
        }
    }
    if (keys[0] != '\0') {
        return sma_message_set(message, "missing key(s) %s for kind %s", keys, repr);
    }
    s.phase_deg = 0.0;
    if (reference_settings(table, &s, message)) {
        reference_signal_free(&s);
        return 1;
    }
    *out = s;
    return 0;
}

int load_from_table(const JsonValue *table, LoadProfile *out, SmaMessage *message)
{
    char keys[TEXT_SIZE], repr[40];
    LoadProfile load;
    size_t values_count = 0, i;
    const JsonValue *times, *values;
    if (unknown_keys(table, -1, keys)) {
        return sma_message_set(message, "unknown key(s) %s; expected times_s, values_kg", keys);
    }
    times = json_object_get(table, "times_s");
    values = json_object_get(table, "values_kg");
    if (times == NULL || values == NULL) {
        return sma_message_set(message, "missing key %s", times == NULL ? "times_s" : "values_kg");
    }
    load.times = load.values = NULL;
    if (numbers_of(times, "times_s", &load.times, &load.count, message)
        || numbers_of(values, "values_kg", &load.values, &values_count, message)) {
        load_profile_free(&load);
        return 1;
    }
    if (load.count != values_count) {
        load_profile_free(&load);
        return sma_message_set(message, "times_s and values_kg must have the same length");
    }
    if (load.times[0] != 0.0) {
        json_float_repr(load.times[0], repr, sizeof repr);
        load_profile_free(&load);
        return sma_message_set(message, "times_s must start at 0, got %s", repr);
    }
    if (increasing(load.times, load.count, "times_s", message)) {
        load_profile_free(&load);
        return 1;
    }
    for (i = 0; i < load.count; i++) {
        if (load.values[i] < 0.0) {
            json_float_repr(load.values[i], repr, sizeof repr);
            load_profile_free(&load);
            return sma_message_set(message, "values_kg must be >= 0, got %s", repr);
        }
    }
    *out = load;
    return 0;
}
