/*
 * timing_input.h - what the bench's timing programs share (inverse_timing.c, stroke_timing.c):
 * this process's CPU time and the numbers they read from stdin. Each program defines
 * TIMING_PROGRAM (its name, for its messages) before it includes this file.
 */
#ifndef SMA_TIMING_INPUT_H
#define SMA_TIMING_INPUT_H

#include <stdio.h>
#include <time.h>

/* This process's CPU time [s] (the machine may be shared). */
static double seconds_now(void)
{
    struct timespec now;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
    return (double)now.tv_sec + 1e-9 * (double)now.tv_nsec;
}

static int read_double(double *value)
{
    if (scanf("%lf", value) != 1) {
        fprintf(stderr, TIMING_PROGRAM ": input ends early\n");
        return 1;
    }
    return 0;
}

#endif
