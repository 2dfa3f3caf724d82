/*
 * compensator_timing.c - what one step of the feedforward compensator costs in the C runtime,
 * for `sma-fmu bench --only hardware` (sma_fmu/bench/compensator.py): the paper's (major
 * inverse, phase-lag filter), the minor-loop inverse, and the demand shaped into the
 * reachable band, with and without anticipating the lower turn.
 *
 * Reads from stdin: the wire's values in PARAMETER_SPECS order ("nan" = not given), alpha [1],
 * beta [s], model_load [kg], adapt_to_load (0/1), the inverse and the shaping (words: major,
 * minor-loop; none, reachable), power_cap [W] ("nan" = none), anticipation L [s], the step h
 * [s], the number of passes, the number of steps K and K pairs (R_ref [ohm], load [kg]).
 * Each pass steps a fresh compensator through the K samples and prints one line: the pass's
 * CPU time [ns per step] and the sum of P_ff [W] (which keeps the compiler from dropping the
 * work). A refusal prints it on stderr, exit 1.
 */
#define _POSIX_C_SOURCE 199309L   /* clock_gettime under -std=c99 */
#define TIMING_PROGRAM "compensator_timing"
#include "timing_input.h"

#include "feedforward.h"

static int fail(const SmaMessage *message)
{
    fprintf(stderr, TIMING_PROGRAM ": %s\n", message->text);
    return 1;
}

int main(void)
{
    static FeedforwardStepper stepper;
    WireParameters params;
    FeedforwardOutputs outputs;
    SmaMessage message;
    char inverse[16], shaping[16];
    double alpha, beta, model_load, adapt, power_cap, lead, step, passes, count, *samples;
    double start, sum;
    long pass, k;
    if (read_wire(&params) || read_double(&alpha) || read_double(&beta)
        || read_double(&model_load) || read_double(&adapt)) {
        return 1;
    }
    if (scanf("%15s %15s", inverse, shaping) != 2) {
        fprintf(stderr, TIMING_PROGRAM ": expected the inverse and the shaping\n");
        return 1;
    }
    if (read_double(&power_cap) || read_double(&lead) || read_double(&step)
        || read_double(&passes) || read_double(&count) || count < 1.0 || count > 1e7
        || read_doubles(2 * (long)count, &samples)) {
        return 1;
    }
    for (pass = 0; pass < (long)passes; pass++) {
        if (feedforward_stepper_init(&stepper, &params, alpha, beta, model_load, adapt != 0.0,
                                     inverse, shaping, power_cap, &message)
            || feedforward_stepper_set_anticipation(&stepper, lead, &message)) {
            return fail(&message);
        }
        sum = 0.0;
        start = seconds_now();
        for (k = 0; k < (long)count; k++) {
            if (feedforward_stepper_step(&stepper, samples[2 * k], samples[2 * k + 1], step,
                                         &outputs, &message)) {
                return fail(&message);
            }
            sum += outputs.P_ff;
        }
        printf("%.3f %.17g\n", (seconds_now() - start) / count * 1e9, sum);
        feedforward_stepper_free(&stepper);
    }
    free(samples);
    return 0;
}
