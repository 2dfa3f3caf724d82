/*
 * sma-fmu's C host: runs an FMU or an SSP package in libcosim (Open Simulation Platform)
 * through its C API (libcosimc, shipped in the libcosimpy wheel), in a process that is not
 * Python, as any C/C++ co-simulation tool would.
 *
 * usage: cosim_host fmu|ssp FILE STEP_S STEPS
 *   runs STEPS fixed steps of STEP_S seconds, then prints one line "slave.variable=value"
 *   (%.17g; Booleans as 0 or 1) for every Real and Boolean output of every slave.
 * Exit status 1 with libcosim's message on stderr on any failure, 2 on a usage error.
 * Built and run by sma_fmu/systems/c_host.py (sma-fmu check, the tests).
 */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

static int fail(const char* what)
{
    fprintf(stderr, "cosim_host: %s failed: %s\n", what, cosim_last_error_message());
    return 1;
}

static cosim_execution* load(const char* kind, const char* path, cosim_duration step)
{
    if (strcmp(kind, "ssp") == 0) return cosim_ssp_fixed_step_execution_create(path, true, 0, step);
    cosim_execution* execution = cosim_execution_create(0, step);
    if (!execution) return NULL;
    cosim_slave* slave = cosim_local_slave_create(path, "fmu");
    if (!slave || cosim_execution_add_slave(execution, slave) < 0) return NULL;
    return execution;
}

static int print_outputs(cosim_execution* execution, cosim_observer* observer,
                         const slave_info* slave)
{
    int count = cosim_slave_get_num_variables(execution, slave->index);
    if (count < 0) return fail("cosim_slave_get_num_variables");
    variable_description* variables = calloc((size_t)count + 1, sizeof *variables);
    if (!variables) return fail("calloc");
    if (cosim_slave_get_variables(execution, slave->index, variables, (size_t)count) < 0) {
        free(variables);
        return fail("cosim_slave_get_variables");
    }
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

int main(int argc, char** argv)
{
    if (argc != 5 || (strcmp(argv[1], "fmu") != 0 && strcmp(argv[1], "ssp") != 0)) {
        fprintf(stderr, "usage: cosim_host fmu|ssp FILE STEP_S STEPS\n");
        return 2;
    }
    const double step = atof(argv[3]);
    const long steps = atol(argv[4]);
    if (!(step > 0.0) || steps < 1) {
        fprintf(stderr, "cosim_host: STEP_S must be > 0 and STEPS >= 1\n");
        return 2;
    }
    cosim_log_set_output_level(LOG_WARNING);
    cosim_execution* execution = load(argv[1], argv[2], (cosim_duration)(step * 1e9 + 0.5));
    if (!execution) return fail("loading the system");
    cosim_observer* observer = cosim_last_value_observer_create();
    if (!observer || cosim_execution_add_observer(execution, observer) != 0)
        return fail("cosim_execution_add_observer");
    if (cosim_execution_step(execution, (size_t)steps) != 0) return fail("cosim_execution_step");

    int count = cosim_execution_get_num_slaves(execution);
    slave_info* slaves = calloc((size_t)count + 1, sizeof *slaves);
    if (!slaves) return fail("calloc");
    if (cosim_execution_get_slave_infos(execution, slaves, (size_t)count) != 0)
        return fail("cosim_execution_get_slave_infos");
    for (int i = 0; i < count; ++i) {
        if (print_outputs(execution, observer, &slaves[i]) != 0) return 1;
    }
    free(slaves);
    cosim_execution_destroy(execution);
    return 0;
}
