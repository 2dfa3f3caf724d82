/*
 * sma-fmu's C host: runs an FMU or an SSP package in libcosim (Open Simulation Platform)
 * through its C API (libcosimc, shipped in the libcosimpy wheel), in a process that is not
 * Python, as any C/C++ co-simulation tool would. libcosim loads the FMUs through the FMI
 * Library.
 *
 * usage: cosim_host [--timing] fmu|ssp FILE STEP_S STEPS [NAME=VALUE...]
 *   sets each Real variable NAME of the FMU to VALUE before initialization (fmu only),
 *   runs STEPS fixed steps of STEP_S seconds, then prints one line "slave.variable=value"
 *   (%.17g; Booleans as 0 or 1) for every Real and Boolean output of every slave (an FMU
 *   run alone is the slave "fmu").
 *   --timing steps one step at a time and first prints "timing P50_US P99_US P999_US TOTAL_S"
 *   (each step's wall time; the first step, which initializes, excluded; STEPS >= 2).
 * Exit status 1 with libcosim's message on stderr on any failure, 2 on a usage error.
 * Built by sma_fmu/fmi/hosts/__init__.py; run by sma-fmu check, the tests and the benchmark.
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

#define NAME_SIZE 1024 /* SLAVE_NAME_MAX_SIZE of cosim.h */
enum { TYPE_REAL = 0, TYPE_BOOLEAN = 3 };
enum { CAUSALITY_OUTPUT = 2 };
enum { LOG_WARNING = 3 };

typedef struct {
    char name[NAME_SIZE];
    cosim_slave_index index;
} slave_info;

typedef struct {
    char name[NAME_SIZE];
    cosim_value_reference reference;
    int type;
    int causality;
    int variability;
} variable_description;

/* prototypes of include/cosim.h (libcosimc) used here */
const char* cosim_last_error_message(void);
void cosim_log_set_output_level(int level);
cosim_execution* cosim_execution_create(cosim_time_point start_time, cosim_duration step_size);
cosim_execution* cosim_ssp_fixed_step_execution_create(const char* ssp_dir, bool start_time_defined,
                                                        cosim_time_point start_time,
                                                        cosim_duration step_size);
cosim_slave* cosim_local_slave_create(const char* fmu_path, const char* instance_name);
cosim_slave_index cosim_execution_add_slave(cosim_execution* execution, cosim_slave* slave);
int cosim_execution_get_num_slaves(cosim_execution* execution);
int cosim_execution_get_slave_infos(cosim_execution* execution, slave_info infos[], size_t count);
int cosim_slave_get_num_variables(cosim_execution* execution, cosim_slave_index slave);
int cosim_slave_get_variables(cosim_execution* execution, cosim_slave_index slave,
                              variable_description variables[], size_t count);
int cosim_execution_set_real_initial_value(cosim_execution* execution, cosim_slave_index slave,
                                           cosim_value_reference vr, double value);
cosim_observer* cosim_last_value_observer_create(void);
int cosim_execution_add_observer(cosim_execution* execution, cosim_observer* observer);
int cosim_execution_step(cosim_execution* execution, size_t num_steps);
int cosim_observer_slave_get_real(cosim_observer* observer, cosim_slave_index slave,
                                  const cosim_value_reference variables[], size_t nv,
                                  double values[]);
int cosim_observer_slave_get_boolean(cosim_observer* observer, cosim_slave_index slave,
                                     const cosim_value_reference variables[], size_t nv,
                                     bool values[]);
int cosim_execution_destroy(cosim_execution* execution);
int cosim_local_slave_destroy(cosim_slave* slave);
int cosim_observer_destroy(cosim_observer* observer);

static const char usage[] = "usage: cosim_host [--timing] fmu|ssp FILE STEP_S STEPS [NAME=VALUE...]\n";

static int fail(const char* what)
{
    fprintf(stderr, "cosim_host: %s failed: %s\n", what, cosim_last_error_message());
    return 1;
}

/* The execution of an SSP, or of an FMU alone (its slave in *slave, its index in *fmu_index);
   NULL on failure. The caller destroys the slave after the execution: libcosim unpacks the FMU
   into a libcosim_<uuid> temporary folder that goes only when both are destroyed. */
static cosim_execution* load(const char* kind, const char* path, cosim_duration step,
                             cosim_slave** slave, cosim_slave_index* fmu_index)
{
    if (strcmp(kind, "ssp") == 0) return cosim_ssp_fixed_step_execution_create(path, true, 0, step);
    cosim_execution* execution = cosim_execution_create(0, step);
    if (!execution) return NULL;
    *slave = cosim_local_slave_create(path, "fmu");
    if (!*slave || (*fmu_index = cosim_execution_add_slave(execution, *slave)) < 0) {
        cosim_execution_destroy(execution);
        return NULL;
    }
    return execution;
}

/* The variables of one slave (count in *count), or NULL after printing why. */
static variable_description* variables_of(cosim_execution* execution, cosim_slave_index slave,
                                          int* count)
{
    *count = cosim_slave_get_num_variables(execution, slave);
    if (*count < 0) {
        fail("cosim_slave_get_num_variables");
        return NULL;
    }
    variable_description* variables = calloc((size_t)*count + 1, sizeof *variables);
    if (!variables) {
        fprintf(stderr, "cosim_host: out of memory\n");
        return NULL;
    }
    if (cosim_slave_get_variables(execution, slave, variables, (size_t)*count) < 0) {
        free(variables);
        fail("cosim_slave_get_variables");
        return NULL;
    }
    return variables;
}

/* Sets each "NAME=VALUE" of assignments[0..n) as the start value of the Real NAME of slave. */
static int set_start_values(cosim_execution* execution, cosim_slave_index slave,
                            char** assignments, int n)
{
    if (n == 0) return 0;
    int count;
    variable_description* variables = variables_of(execution, slave, &count);
    if (!variables) return 1;
    int status = 0;
    for (int a = 0; a < n && status == 0; ++a) {
        const char* equals = strchr(assignments[a], '=');
        char* end = NULL;
        double value = equals ? strtod(equals + 1, &end) : 0.0;
        if (!equals || end == equals + 1 || *end != '\0') {
            fprintf(stderr, "cosim_host: bad start value '%s' (expected NAME=VALUE)\n", assignments[a]);
            status = 2;
            break;
        }
        size_t length = (size_t)(equals - assignments[a]);
        const variable_description* found = NULL;
        for (int i = 0; i < count && !found; ++i) {
            if (strlen(variables[i].name) == length
                && strncmp(variables[i].name, assignments[a], length) == 0) found = &variables[i];
        }
        if (!found || found->type != TYPE_REAL) {
            fprintf(stderr, "cosim_host: the FMU has no Real variable '%.*s'\n", (int)length,
                    assignments[a]);
            status = 2;
        } else if (cosim_execution_set_real_initial_value(execution, slave, found->reference, value) != 0) {
            status = fail("cosim_execution_set_real_initial_value");
        }
    }
    free(variables);
    return status;
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int by_value(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

/* Steps one at a time, timing each step after the first; prints the percentiles. */
static int timed_steps(cosim_execution* execution, long steps)
{
    if (cosim_execution_step(execution, 1) != 0) return fail("cosim_execution_step");
    const long n = steps - 1;
    double* cost = malloc(sizeof(double) * (size_t)n);
    if (!cost) {
        fprintf(stderr, "cosim_host: out of memory\n");
        return 1;
    }
    const double start = now();
    for (long i = 0; i < n; ++i) {
        const double before = now();
        if (cosim_execution_step(execution, 1) != 0) {
            free(cost);
            return fail("cosim_execution_step");
        }
        cost[i] = now() - before;
    }
    const double total = now() - start;
    qsort(cost, (size_t)n, sizeof(double), by_value);
    printf("timing %.3f %.3f %.3f %.6f\n", 1e6 * cost[n / 2], 1e6 * cost[(long)((double)n * 0.99)],
           1e6 * cost[(long)((double)n * 0.999)], total);
    free(cost);
    return 0;
}

static int print_outputs(cosim_execution* execution, cosim_observer* observer,
                         const slave_info* slave)
{
    int count;
    variable_description* variables = variables_of(execution, slave->index, &count);
    if (!variables) return 1;
    for (int i = 0; i < count; ++i) {
        const variable_description* v = &variables[i];
        if (v->causality != CAUSALITY_OUTPUT) continue;
        if (v->type == TYPE_REAL) {
            double value;
            if (cosim_observer_slave_get_real(observer, slave->index, &v->reference, 1, &value) != 0) {
                free(variables);
                return fail("cosim_observer_slave_get_real");
            }
            printf("%s.%s=%.17g\n", slave->name, v->name, value);
        } else if (v->type == TYPE_BOOLEAN) {
            bool value;
            if (cosim_observer_slave_get_boolean(observer, slave->index, &v->reference, 1, &value) != 0) {
                free(variables);
                return fail("cosim_observer_slave_get_boolean");
            }
            printf("%s.%s=%d\n", slave->name, v->name, value ? 1 : 0);
        }
    }
    free(variables);
    return 0;
}

/* Set the start values, step, print every slave's outputs; 0 or the failure's status. The
   observer it adds is left in *observer for the caller to destroy. */
static int run_and_print(cosim_execution* execution, cosim_slave_index fmu_index, char** values,
                         int nvalues, bool timing, long steps, cosim_observer** observer)
{
    int status = set_start_values(execution, fmu_index, values, nvalues);
    if (status != 0) return status;
    *observer = cosim_last_value_observer_create();
    if (!*observer || cosim_execution_add_observer(execution, *observer) != 0)
        return fail("cosim_execution_add_observer");
    if (timing) {
        if (timed_steps(execution, steps) != 0) return 1;
    } else if (cosim_execution_step(execution, (size_t)steps) != 0) {
        return fail("cosim_execution_step");
    }
    int count = cosim_execution_get_num_slaves(execution);
    slave_info* slaves = calloc((size_t)count + 1, sizeof *slaves);
    if (!slaves) return fail("calloc");
    status = cosim_execution_get_slave_infos(execution, slaves, (size_t)count) != 0
                 ? fail("cosim_execution_get_slave_infos") : 0;
    for (int i = 0; i < count && status == 0; ++i) {
        status = print_outputs(execution, *observer, &slaves[i]) != 0 ? 1 : 0;
    }
    free(slaves);
    return status;
}

int main(int argc, char** argv)
{
    const bool timing = argc > 1 && strcmp(argv[1], "--timing") == 0;
    char** args = argv + (timing ? 1 : 0);
    const int nargs = argc - (timing ? 1 : 0);
    if (nargs < 5 || (strcmp(args[1], "fmu") != 0 && strcmp(args[1], "ssp") != 0)) {
        fputs(usage, stderr);
        return 2;
    }
    const bool fmu = strcmp(args[1], "fmu") == 0;
    const double step = atof(args[3]);
    const long steps = atol(args[4]);
    if (!(step > 0.0) || steps < (timing ? 2 : 1)) {
        fprintf(stderr, "cosim_host: STEP_S must be > 0 and STEPS >= %d\n", timing ? 2 : 1);
        return 2;
    }
    if (!fmu && nargs > 5) {
        fprintf(stderr, "cosim_host: start values (NAME=VALUE) are for an FMU, not an SSP\n");
        return 2;
    }
    cosim_log_set_output_level(LOG_WARNING);
    cosim_slave_index fmu_index = 0;
    cosim_slave* slave = NULL;
    cosim_execution* execution = load(args[1], args[2], (cosim_duration)(step * 1e9 + 0.5), &slave,
                                      &fmu_index);
    if (!execution) {
        int failed = fail("loading the system");
        cosim_local_slave_destroy(slave);
        return failed;
    }
    cosim_observer* observer = NULL;
    int status = run_and_print(execution, fmu_index, args + 5, nargs - 5, timing, steps, &observer);
    cosim_execution_destroy(execution);   /* then what it used: its temporary folders go */
    cosim_observer_destroy(observer);
    cosim_local_slave_destroy(slave);
    return status;
}
