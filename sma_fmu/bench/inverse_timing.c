/*
 * inverse_timing.c - what one temperature-sensing inversion costs in the C runtime, for
 * `sma-fmu bench --only inverse` (sma_fmu/bench/inverse.py).
 *
 * Reads from stdin: the wire's values in PARAMETER_SPECS order ("nan" = not given), the load
 * [kg], the direction (+1/-1), the number of passes, the number of targets K and K pairs
 * (xi_MF, xi_P) [1]. Each pass inverts every target with temperature_of_fractions (the
 * branch constants built once, as a compensator at a steady load does) and prints one line:
 * the pass's CPU time [ns per inversion] and the sum of the sensed temperatures [degC] (which
 * keeps the compiler from dropping the work). A refusal prints it on stderr, exit 1.
 */
#define _POSIX_C_SOURCE 199309L   /* clock_gettime under -std=c99 */
#define TIMING_PROGRAM "inverse_timing"
#include "timing_input.h"

#include "constant_load.h"
#include "sensing.h"

int main(void)
{
    WireParameters params;
    BranchConstants constants;
    SensedTemperature sensed;
    SmaMessage message;
    double load, direction, passes, count, *targets, start, sum;
    long pass, k;
    if (read_wire(&params) || read_double(&load) || read_double(&direction)
        || read_double(&passes) || read_double(&count) || count < 1.0 || count > 1e7
        || read_doubles(2 * (long)count, &targets)) {
        return 1;
    }
    if (branch_constants(load, direction > 0.0 ? 1 : -1, &params, &constants, &message)) {
        fprintf(stderr, "%s\n", message.text);
        return 1;
    }
    for (pass = 0; pass < (long)passes; pass++) {
        sum = 0.0;
        start = seconds_now();
        for (k = 0; k < (long)count; k++) {
            if (temperature_of_fractions(targets[2 * k], targets[2 * k + 1], &constants,
                                         params.saturation_margin, &sensed, &message)) {
                fprintf(stderr, "%s\n", message.text);
                return 1;
            }
            sum += sensed.temperature;
        }
        printf("%.6f %.17g\n", (seconds_now() - start) / count * 1e9, sum);
    }
    free(targets);
    return 0;
}
