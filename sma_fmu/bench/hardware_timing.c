/*
 * hardware_timing.c - what the bench hardware blocks cost per step in the C runtime, for
 * `sma-fmu bench --only hardware` (sma_fmu/bench/hardware.py).
 *
 * Reads from stdin the number of passes and the steps per pass. Each pass times each block
 * over that many steps (the inputs of a wire near 40 ohm, 1-ms steps) and prints one line per
 * block: its name, the CPU time [ns per step] and the sum of its outputs (which keeps the
 * compiler from dropping the work). A refusal prints it on stderr, exit 1.
 */
#define _POSIX_C_SOURCE 199309L   /* clock_gettime under -std=c99 */
#define TIMING_PROGRAM "hardware_timing"
#include "timing_input.h"

#include "drive_limit.h"
#include "measurement.h"
#include "noise.h"
#include "pi_control.h"
#include "pwm.h"

static double wire(long k)   /* a resistance that moves a little every step [ohm] */
{
    return 40.0 + (double)(k % 1000) * 1e-3;
}

static void report(const char *name, double start, long steps, double sum)
{
    printf("%s %.6f %.17g\n", name, (seconds_now() - start) / (double)steps * 1e9, sum);
}

static int fail(const SmaMessage *message)
{
    fprintf(stderr, "%s\n", message->text);
    return 1;
}

int main(void)
{
    long passes, steps, pass, k;
    SmaMessage message;
    ResistanceSensor sensor;
    SensedPIController sensed;
    PIController plain;
    DriveLimit limit;
    LinearDriver linear;
    PwmDriver pwm, limited;
    double start, sum, power, feedback, measured;
    if (scanf("%ld %ld", &passes, &steps) != 2 || passes < 1 || steps < 1) {
        fprintf(stderr, "hardware_timing: expected PASSES STEPS\n");
        return 1;
    }
    if (resistance_sensor_init(&sensor, 0.05, 65.536, 16, 1, &message)
        || pi_controller_init(&plain, 0.3, 1.0, &message)
        || pi_controller_init(&sensed.pi, 0.3, 1.0, &message)
        || resistance_sensor_init(&sensed.sensor, 0.05, 65.536, 16, 1, &message)
        || drive_limit_init(&limit, 0.5, 24.0, &message)
        || pwm_driver_init(&pwm, 50.0, 8.0, &message)
        || pwm_driver_init(&limited, 50.0, 8.0, &message)) {
        return fail(&message);
    }
    linear_driver_init(&linear, &limit);
    pwm_driver_set_limit(&limited, &limit);
    for (pass = 0; pass < passes; pass++) {
        sum = 0.0;
        start = seconds_now();
        for (k = 0; k < steps; k++) sum += standard_normal(1, (uint64_t)k);
        report("noise", start, steps, sum);
        sum = 0.0;
        start = seconds_now();
        for (k = 0; k < steps; k++) {
            if (resistance_sensor_measure(&sensor, wire(k), &measured, &message)) return fail(&message);
            sum += measured;
        }
        report("sensor", start, steps, sum);
        sum = 0.0;
        start = seconds_now();
        for (k = 0; k < steps; k++) {
            if (pi_controller_sample(&plain, wire(k), 41.0, 1.0, 1e-3, &power, &feedback, &message))
                return fail(&message);
            sum += power;
        }
        report("pi", start, steps, sum);
        sum = 0.0;
        start = seconds_now();
        for (k = 0; k < steps; k++) {
            if (sensed_pi_sample(&sensed, wire(k), 41.0, 1.0, 1e-3, &power, &feedback, &measured,
                                 &message))
                return fail(&message);
            sum += power;
        }
        report("sensed_pi", start, steps, sum);
        sum = 0.0;
        start = seconds_now();
        for (k = 0; k < steps; k++) {
            if (linear_driver_step(&linear, 12.0, (double)k * 1e-3, 1e-3, wire(k), &power, &message))
                return fail(&message);
            sum += power;
        }
        report("linear_limited", start, steps, sum);
        sum = 0.0;
        start = seconds_now();
        for (k = 0; k < steps; k++) {
            if (pwm_driver_step(&pwm, 5.0, (double)k * 1e-3, 1e-3, &power, &message))
                return fail(&message);
            sum += power;
        }
        report("pwm", start, steps, sum);
        sum = 0.0;
        start = seconds_now();
        for (k = 0; k < steps; k++) {
            if (pwm_driver_step_limited(&limited, 5.0, (double)k * 1e-3, 1e-3, wire(k), &power,
                                        &message))
                return fail(&message);
            sum += power;
        }
        report("pwm_limited", start, steps, sum);
    }
    return 0;
}
