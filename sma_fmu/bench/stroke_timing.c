/*
 * stroke_timing.c - what one stroke -> R_ref mapping costs in the C runtime, for
 * `sma-fmu bench --only stroke` (sma_fmu/bench/stroke.py).
 *
 * Reads from stdin: the wire's values in PARAMETER_SPECS order ("nan" = not given), the start
 * length x_0 [m], the load [kg], the direction (+1/-1), the number of passes, the number of
 * strokes K and K strokes [m]. Each pass maps every stroke with a fresh map (so none is the
 * kept last target) and prints one line: the pass's CPU time [ns per mapping] and the sum of
 * the R_ref [ohm] (which keeps the compiler from dropping the work). A refusal prints it on
 * stderr, exit 1.
 */
#define _POSIX_C_SOURCE 199309L   /* clock_gettime under -std=c99 */
#define TIMING_PROGRAM "stroke_timing"
#include "timing_input.h"

#include "stroke.h"

int main(void)
{
    static StrokeMap map;
    WireParameters params;
    StrokeTarget target;
    SmaMessage message;
    double start_length, load, direction, passes, count, *strokes, start, sum;
    long pass, k;
    if (read_wire(&params) || read_double(&start_length) || read_double(&load)
        || read_double(&direction) || read_double(&passes) || read_double(&count)
        || count < 1.0 || count > 1e7 || read_doubles((long)count, &strokes)) {
        return 1;
    }
    for (pass = 0; pass < (long)passes; pass++) {
        stroke_map_init(&map, &params, start_length);
        sum = 0.0;
        start = seconds_now();
        for (k = 0; k < (long)count; k++) {
            if (stroke_map_target(&map, strokes[k], load, (int)direction, &target, &message)) {
                fprintf(stderr, "stroke_timing: %s\n", message.text);
                return 1;
            }
            sum += target.R_ref;
        }
        printf("%.3f %.17g\n", (seconds_now() - start) / count * 1e9, sum);
    }
    free(strokes);
    return 0;
}
