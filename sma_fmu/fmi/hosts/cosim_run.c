/*
 * A C host for the FMUs, built on libcosim's C API (libcosimc, Open Simulation Platform;
 * shipped in the libcosimpy wheel). libcosim loads the FMU through the FMI Library, like
 * any C/C++ co-simulation tool would, in a process that is not Python.
 *
 * usage: cosim_run FMU STEP_S STEPS VR=VALUE... -- OUT_VR...
 *   sets each input/parameter VR to VALUE before initialization, runs STEPS fixed steps
 *   of STEP_S seconds, then prints "VR=value" (%.17g) for each OUT_VR. With
 *   COSIM_RUN_TIMING=1 it steps one step at a time and also prints
 *   "timing P50_US P99_US P999_US TOTAL_S" (each step's wall time, first step excluded).
 * Exit status 1 with libcosim's message on stderr on any failure.
 */
#define _POSIX_C_SOURCE 199309L
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef int64_t cosim_time_point;
typedef int64_t cosim_duration;
typedef uint32_t cosim_value_reference;
typedef int cosim_slave_index;
typedef struct cosim_execution_s cosim_execution;
typedef struct cosim_slave_s cosim_slave;
typedef struct cosim_observer_s cosim_observer;

/* prototypes of include/cosim.h (libcosimc) used here */
const char* cosim_last_error_message(void);
cosim_execution* cosim_execution_create(cosim_time_point start_time, cosim_duration step_size);
cosim_slave* cosim_local_slave_create(const char* fmu_path, const char* instance_name);
cosim_slave_index cosim_execution_add_slave(cosim_execution* execution, cosim_slave* slave);
int cosim_execution_set_real_initial_value(cosim_execution* execution, cosim_slave_index slave,
                                           cosim_value_reference vr, double value);
cosim_observer* cosim_last_value_observer_create(void);
int cosim_execution_add_observer(cosim_execution* execution, cosim_observer* observer);
int cosim_execution_step(cosim_execution* execution, size_t num_steps);
int cosim_observer_slave_get_real(cosim_observer* observer, cosim_slave_index slave,
                                  const cosim_value_reference variables[], size_t nv,
                                  double values[]);
int cosim_execution_destroy(cosim_execution* execution);

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static int by_value(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

/* Steps one at a time, timing each; prints the percentiles. */
static int timed_steps(cosim_execution* execution, long steps)
{
    if (cosim_execution_step(execution, 1) != 0) return -1; /* the first step initializes */
    double* cost = malloc(sizeof(double) * (size_t)steps);
    double start = now();
    for (long i = 1; i < steps; ++i) {
        double before = now();
        if (cosim_execution_step(execution, 1) != 0) { free(cost); return -1; }
        cost[i - 1] = now() - before;
    }
    double total = now() - start;
    long n = steps - 1;
    qsort(cost, (size_t)n, sizeof(double), by_value);
    printf("timing %.3f %.3f %.3f %.6f\n", 1e6 * cost[n / 2], 1e6 * cost[(long)(n * 0.99)],
           1e6 * cost[(long)(n * 0.999)], total);
    free(cost);
    return 0;
}

static int fail(const char* what)
{
    fprintf(stderr, "cosim_run: %s failed: %s\n", what, cosim_last_error_message());
    return 1;
}

int main(int argc, char** argv)
{
    if (argc < 5) {
        fprintf(stderr, "usage: cosim_run FMU STEP_S STEPS VR=VALUE... -- OUT_VR...\n");
        return 2;
    }
    const double step = atof(argv[2]);
    const long steps = atol(argv[3]);
    cosim_execution* execution = cosim_execution_create(0, (cosim_duration)(step * 1e9 + 0.5));
    if (!execution) return fail("cosim_execution_create");
    cosim_slave* slave = cosim_local_slave_create(argv[1], "instance");
    if (!slave) return fail("cosim_local_slave_create");
    cosim_slave_index index = cosim_execution_add_slave(execution, slave);
    if (index < 0) return fail("cosim_execution_add_slave");

    int arg = 4;
    for (; arg < argc && strcmp(argv[arg], "--") != 0; ++arg) {
        unsigned vr;
        double value;
        if (sscanf(argv[arg], "%u=%lf", &vr, &value) != 2) {
            fprintf(stderr, "cosim_run: bad assignment '%s'\n", argv[arg]);
            return 2;
        }
        if (cosim_execution_set_real_initial_value(execution, index, vr, value) != 0)
            return fail("cosim_execution_set_real_initial_value");
    }
    cosim_observer* observer = cosim_last_value_observer_create();
    if (!observer || cosim_execution_add_observer(execution, observer) != 0)
        return fail("cosim_execution_add_observer");
    const char* timing = getenv("COSIM_RUN_TIMING");
    if (timing && *timing == '1' && steps > 1) {
        if (timed_steps(execution, steps) != 0) return fail("cosim_execution_step");
    } else if (cosim_execution_step(execution, (size_t)steps) != 0) {
        return fail("cosim_execution_step");
    }

    for (++arg; arg < argc; ++arg) {
        cosim_value_reference vr = (cosim_value_reference)strtoul(argv[arg], NULL, 10);
        double value;
        if (cosim_observer_slave_get_real(observer, index, &vr, 1, &value) != 0)
            return fail("cosim_observer_slave_get_real");
        printf("%u=%.17g\n", vr, value);
    }
    cosim_execution_destroy(execution);
    return 0;
}
