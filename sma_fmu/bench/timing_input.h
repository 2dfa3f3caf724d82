/*
 * timing_input.h - what the bench's timing programs share (inverse_timing.c, stroke_timing.c,
 * hardware_timing.c, compensator_timing.c): this process's CPU time, the numbers they read
 * from stdin and the wire they read (static inline: a program that uses some of them gets no
 * warning for the others). Each program defines TIMING_PROGRAM (its name, for its messages)
 * before it includes this file.
 */
#ifndef SMA_TIMING_INPUT_H
#define SMA_TIMING_INPUT_H

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "parameters.h"

/* This process's CPU time [s] (the machine may be shared). */
static inline double seconds_now(void)
{
    struct timespec now;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
    return (double)now.tv_sec + 1e-9 * (double)now.tv_nsec;
}

static inline int read_double(double *value)
{
    if (scanf("%lf", value) != 1) {
        fprintf(stderr, TIMING_PROGRAM ": input ends early\n");
        return 1;
    }
    return 0;
}

/* `count` numbers into a new array *out (free it); 1 (said on stderr) when the input ends. */
static inline int read_doubles(long count, double **out)
{
    long k;
    *out = malloc(sizeof(double) * (size_t)(count > 0 ? count : 1));
    if (*out == NULL) {
        fprintf(stderr, TIMING_PROGRAM ": out of memory\n");
        return 1;
    }
    for (k = 0; k < count; k++) {
        if (read_double(&(*out)[k])) {
            return 1;
        }
    }
    return 0;
}

/* The wire: its values in PARAMETER_SPECS order ("nan" = not given), checked as the FMUs
 * check them; 1 (said on stderr) when the input ends or the values are refused. */
static inline int read_wire(WireParameters *params)
{
    static double values[PARAM_COUNT];
    SmaMessage message;
    long i;
    for (i = 0; i < PARAM_COUNT; i++) {
        if (read_double(&values[i])) {
            return 1;
        }
    }
    if (wire_parameters_from_values(params, values, &message)) {
        fprintf(stderr, TIMING_PROGRAM ": %s\n", message.text);
        return 1;
    }
    return 0;
}

#endif
