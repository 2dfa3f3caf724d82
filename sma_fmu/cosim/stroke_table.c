/*
 * stroke_table.c - a stroke reference's R_ref at every step in C, for the C master
 * (sma_fmu/cosim/stroke_table.py): StrokeReference.value of runtime/stroke.py at t_k = k h,
 * with the C runtime's signals and stroke map (equal to Python's to the double), so the C
 * master does not map 30 000 steps in Python.
 *
 * Reads from stdin (numbers as Python's repr writes them, "nan" = not given): the wire's
 * values in PARAMETER_SPECS order, the start length x_0 [m], the stroke signal's kind (its
 * index in REFERENCE_KINDS) and its settings [mm, s, Hz, deg] in the kind's order (constant:
 * value; step: initial, final, time; ramp: start, end, start time, end time; sine, cosine:
 * offset, amplitude, frequency, phase; table: count, times, values), the load profile (count,
 * times [s], values [kg]), the step h [s] and the number of steps. Writes R_ref [ohm] at
 * t_k = k h, k = 0 ... steps, on stdout as raw doubles (the machine's byte order). A refusal
 * prints its message on stderr, exit 1.
 */
#include <stdio.h>
#include <stdlib.h>

#include "parameters.h"
#include "signals.h"
#include "stroke.h"

#define NAME "stroke_table"

static int read_double(double *value)
{
    if (scanf("%lf", value) != 1) {
        fprintf(stderr, NAME ": input ends early\n");
        return 1;
    }
    return 0;
}

/* count doubles into a new array *out (count read first) */
static int read_array(size_t *count, double **out)
{
    double number;
    size_t i;
    if (read_double(&number) || !(number >= 1.0 && number < 1e9)) {
        fprintf(stderr, NAME ": bad array length\n");
        return 1;
    }
    *count = (size_t)number;
    *out = malloc(sizeof(double) * *count);
    if (*out == NULL) {
        fprintf(stderr, NAME ": out of memory\n");
        return 1;
    }
    for (i = 0; i < *count; i++) {
        if (read_double(&(*out)[i])) {
            return 1;
        }
    }
    return 0;
}

static int read_signal(ReferenceSignal *s)
{
    static const int SETTINGS[REFERENCE_KIND_COUNT] = {1, 3, 4, 4, 4, 0};
    double kind, v[4];
    int i;
    size_t count;
    if (read_double(&kind) || !(kind >= 0.0 && kind < REFERENCE_KIND_COUNT)) {
        fprintf(stderr, NAME ": bad reference kind\n");
        return 1;
    }
    s->kind = (ReferenceKind)(int)kind;
    for (i = 0; i < SETTINGS[s->kind]; i++) {
        if (read_double(&v[i])) {
            return 1;
        }
    }
    switch (s->kind) {
    case REFERENCE_CONSTANT:
        s->value_ohm = v[0];
        return 0;
    case REFERENCE_STEP:
        s->initial_ohm = v[0], s->final_ohm = v[1], s->time_s = v[2];
        return 0;
    case REFERENCE_RAMP:
        s->start_ohm = v[0], s->end_ohm = v[1], s->start_time_s = v[2], s->end_time_s = v[3];
        return 0;
    case REFERENCE_SINE:
    case REFERENCE_COSINE:
        s->offset_ohm = v[0], s->amplitude_ohm = v[1], s->frequency_hz = v[2], s->phase_deg = v[3];
        return 0;
    default:
        if (read_array(&s->count, &s->times_s) || read_array(&count, &s->values_ohm)
            || count != s->count) {
            fprintf(stderr, NAME ": the table's times and values differ in length\n");
            return 1;
        }
        return 0;
    }
}

int main(void)
{
    static double values[PARAM_COUNT];
    static StrokeMap map;
    static const ReferenceSignal empty;
    ReferenceSignal signal = empty;
    LoadProfile load = {0, NULL, NULL};
    WireParameters params;
    StrokeTarget target;
    SmaMessage message;
    double start_length, step_s, steps_read, t, stroke, *r_ref;
    size_t steps, k, load_values;
    int i;
    for (i = 0; i < PARAM_COUNT; i++) {
        if (read_double(&values[i])) {
            return 1;
        }
    }
    if (read_double(&start_length) || read_signal(&signal)
        || read_array(&load.count, &load.times) || read_array(&load_values, &load.values)
        || read_double(&step_s) || read_double(&steps_read)) {
        return 1;
    }
    if (load_values != load.count || !(steps_read >= 1.0 && steps_read < 1e10)) {
        fprintf(stderr, NAME ": bad load profile or number of steps\n");
        return 1;
    }
    if (wire_parameters_from_values(&params, values, &message)) {
        fprintf(stderr, NAME ": %s\n", message.text);
        return 1;
    }
    steps = (size_t)steps_read;
    r_ref = malloc(sizeof(double) * (steps + 1));
    if (r_ref == NULL) {
        fprintf(stderr, NAME ": out of memory\n");
        return 1;
    }
    stroke_map_init(&map, &params, start_length);
    for (k = 0; k <= steps; k++) {   /* StrokeReference.value(t_k) */
        t = (double)k * step_s;
        if (reference_signal_value(&signal, t, &stroke, &message)
            || stroke_map_target(&map, 1e-3 * stroke, load_profile_value(&load, t, LOAD_TOLERANCE_S),
                                 reference_signal_trend(&signal, t), &target, &message)) {
            fprintf(stderr, NAME ": %s\n", message.text);
            return 1;
        }
        r_ref[k] = target.R_ref;
    }
    if (fwrite(r_ref, sizeof(double), steps + 1, stdout) != steps + 1) {
        fprintf(stderr, NAME ": could not write the table\n");
        return 1;
    }
    reference_signal_free(&signal);
    load_profile_free(&load);
    free(r_ref);
    return fflush(stdout) != 0;
}
