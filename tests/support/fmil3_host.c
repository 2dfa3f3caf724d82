/* A small FMI 3.0 co-simulation host on the FMI Library (FMIL) 3.0.4: a by-hand tool, not
 * built or run by the tests or CI (the FMI Library is in no package registry). How to build
 * the library and this host, and what it measured: docs/systems.md, "FMI 3.0 hosts built by
 * hand".
 *
 * Usage: fmil3_host FMU [--stop T] [--step H] [--event-mode] [--set NAME VALUE]...
 *                       [--output-file CSV]
 *
 * Unpacks FMU into a fresh folder under /tmp, parses its model description with the FMI
 * Library, loads the co-simulation binary, instantiates it (logging on), sets each --set
 * Float64 variable (before initialization: a start value, or a constant input), initializes,
 * steps from 0 to T (default 1 s) at H (default 1 ms) and reads every output (Float64,
 * Int32, Int64 and Enumeration, Boolean) after each step, then terminates and frees.
 * With --event-mode the instance is made with eventModeUsed and earlyReturnAllowed: a step
 * that asks for event handling is followed by Event Mode (fmi3UpdateDiscreteStates until no
 * update is needed) and back to Step Mode, and an early return makes the next step start at
 * lastSuccessfulTime.
 *
 * Printed: every message the FMU logs ("[FMU <status>] <category>: <message>") and every
 * message the FMI Library logs at warning level or above ("[FMIL <level>] <module>:
 * <message>"), an error line for each call that returns fmi3Error or fmi3Fatal, and a last
 * line "fmil3_host: <model>: <steps> steps to <time> s, <events> event(s), <early> early
 * return(s), <warnings> warning line(s), <errors> error line(s) (<n> from the FMI Library)".
 * Exit status 0 when no error line was printed, 1 otherwise, 2 for a usage error.
 * --output-file writes the outputs after each step (and at the start) as CSV, %.17g. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fmilib.h>

#define MAX_SETS 32

static int warning_lines;
static int error_lines;
static int library_error_lines; /* of error_lines: those the FMI Library itself logged */

static void library_logger(jm_callbacks *callbacks, jm_string module, jm_log_level_enu_t level,
                           jm_string message)
{
    (void)callbacks;
    if (level > jm_log_level_warning)
        return;
    if (level == jm_log_level_warning)
        warning_lines++;
    else {
        error_lines++;
        library_error_lines++;
    }
    printf("[FMIL %s] %s: %s\n", jm_log_level_to_string(level), module, message);
}

static void fmu_logger(fmi3_instance_environment_t environment, fmi3_status_t status,
                       fmi3_string_t category, fmi3_string_t message)
{
    (void)environment;
    if (status == fmi3_status_warning)
        warning_lines++;
    else if (status >= fmi3_status_discard)
        error_lines++;
    printf("[FMU %s] %s: %s\n", fmi3_status_to_string(status), category ? category : "",
           message ? message : "");
}

/* status of an FMI call: warnings counted, error and fatal printed and counted; nonzero if
 * the host must stop */
static int checked(fmi3_status_t status, const char *call)
{
    if (status == fmi3_status_ok)
        return 0;
    if (status == fmi3_status_warning) {
        warning_lines++;
        printf("[HOST Warning] %s returned fmi3Warning\n", call);
        return 0;
    }
    if (status == fmi3_status_discard) {
        error_lines++;
        printf("[HOST Error] %s returned fmi3Discard\n", call);
        return 1;
    }
    error_lines++;
    printf("[HOST Error] %s returned %s\n", call, fmi3_status_to_string(status));
    return 1;
}

/* the outputs, grouped by how they are read */
struct outputs {
    size_t n_float64, n_int32, n_int64, n_boolean;
    fmi3_value_reference_t *vr_float64, *vr_int32, *vr_int64, *vr_boolean;
    const char **name_float64, **name_int32, **name_int64, **name_boolean;
    fmi3_float64_t *float64;
    fmi3_int32_t *int32;
    fmi3_int64_t *int64;
    fmi3_boolean_t *boolean;
};

static void add_output(struct outputs *o, fmi3_import_variable_t *v)
{
    fmi3_value_reference_t vr = fmi3_import_get_variable_vr(v);
    const char *name = fmi3_import_get_variable_name(v);
    if (fmi3_import_variable_is_array(v)) { /* scalars only: the outputs a loop connects */
        printf("[HOST Note] output %s: an array, not read\n", name);
        return;
    }
    switch (fmi3_import_get_variable_base_type(v)) {
    case fmi3_base_type_float64:
        o->vr_float64[o->n_float64] = vr;
        o->name_float64[o->n_float64++] = name;
        break;
    case fmi3_base_type_int32:
        o->vr_int32[o->n_int32] = vr;
        o->name_int32[o->n_int32++] = name;
        break;
    case fmi3_base_type_int64:
    case fmi3_base_type_enum:
        o->vr_int64[o->n_int64] = vr;
        o->name_int64[o->n_int64++] = name;
        break;
    case fmi3_base_type_bool:
        o->vr_boolean[o->n_boolean] = vr;
        o->name_boolean[o->n_boolean++] = name;
        break;
    default:
        warning_lines++;
        printf("[HOST Warning] output %s: a type this host does not read\n", name);
    }
}

static int read_outputs(fmi3_import_t *fmu, struct outputs *o)
{
    if (o->n_float64 && checked(fmi3_import_get_float64(fmu, o->vr_float64, o->n_float64,
                                                        o->float64, o->n_float64), "fmi3GetFloat64"))
        return 1;
    if (o->n_int32 && checked(fmi3_import_get_int32(fmu, o->vr_int32, o->n_int32, o->int32,
                                                    o->n_int32), "fmi3GetInt32"))
        return 1;
    if (o->n_int64 && checked(fmi3_import_get_int64(fmu, o->vr_int64, o->n_int64, o->int64,
                                                    o->n_int64), "fmi3GetInt64"))
        return 1;
    if (o->n_boolean && checked(fmi3_import_get_boolean(fmu, o->vr_boolean, o->n_boolean,
                                                        o->boolean, o->n_boolean), "fmi3GetBoolean"))
        return 1;
    return 0;
}

static void write_header(FILE *out, const struct outputs *o)
{
    size_t k;
    fprintf(out, "time");
    for (k = 0; k < o->n_float64; k++) fprintf(out, ",%s", o->name_float64[k]);
    for (k = 0; k < o->n_int32; k++) fprintf(out, ",%s", o->name_int32[k]);
    for (k = 0; k < o->n_int64; k++) fprintf(out, ",%s", o->name_int64[k]);
    for (k = 0; k < o->n_boolean; k++) fprintf(out, ",%s", o->name_boolean[k]);
    fprintf(out, "\n");
}

static void write_row(FILE *out, double time, const struct outputs *o)
{
    size_t k;
    fprintf(out, "%.17g", time);
    for (k = 0; k < o->n_float64; k++) fprintf(out, ",%.17g", o->float64[k]);
    for (k = 0; k < o->n_int32; k++) fprintf(out, ",%d", (int)o->int32[k]);
    for (k = 0; k < o->n_int64; k++) fprintf(out, ",%lld", (long long)o->int64[k]);
    for (k = 0; k < o->n_boolean; k++) fprintf(out, ",%d", o->boolean[k] ? 1 : 0);
    fprintf(out, "\n");
}

/* Event Mode after a step that asked for it, then back to Step Mode */
static int handle_event(fmi3_import_t *fmu)
{
    fmi3_boolean_t update = fmi3_true, terminate = fmi3_false, nominals, values, defined;
    fmi3_float64_t next;
    int rounds = 0;
    if (checked(fmi3_import_enter_event_mode(fmu), "fmi3EnterEventMode"))
        return 1;
    while (update) {
        if (checked(fmi3_import_update_discrete_states(fmu, &update, &terminate, &nominals,
                                                       &values, &defined, &next),
                    "fmi3UpdateDiscreteStates"))
            return 1;
        if (terminate || ++rounds > 100) {
            error_lines++;
            printf("[HOST Error] fmi3UpdateDiscreteStates: %s\n",
                   terminate ? "the FMU asks to terminate" : "no fixed point after 100 rounds");
            return 1;
        }
    }
    return checked(fmi3_import_enter_step_mode(fmu), "fmi3EnterStepMode");
}

static void usage(void)
{
    fprintf(stderr, "usage: fmil3_host FMU [--stop T] [--step H] [--event-mode] "
                    "[--set NAME VALUE]... [--output-file CSV]\n");
}

int main(int argc, char **argv)
{
    const char *fmu_path = NULL, *output_path = NULL;
    const char *set_names[MAX_SETS];
    double set_values[MAX_SETS];
    int n_sets = 0, event_mode = 0, failed = 1, instantiated = 0, dll = 0;
    double stop = 1.0, step = 1e-3, time = 0.0;
    long steps = 0, events = 0, early_returns = 0;
    char folder[] = "/tmp/fmil3_host_XXXXXX";
    jm_callbacks callbacks;
    fmi_import_context_t *context = NULL;
    fmi3_import_t *fmu = NULL;
    fmi3_import_variable_list_t *variables = NULL;
    struct outputs o;
    FILE *out = NULL;
    size_t k, n;
    int i;

    memset(&o, 0, sizeof o);
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--stop") && i + 1 < argc)
            stop = atof(argv[++i]);
        else if (!strcmp(argv[i], "--step") && i + 1 < argc)
            step = atof(argv[++i]);
        else if (!strcmp(argv[i], "--event-mode"))
            event_mode = 1;
        else if (!strcmp(argv[i], "--output-file") && i + 1 < argc)
            output_path = argv[++i];
        else if (!strcmp(argv[i], "--set") && i + 2 < argc && n_sets < MAX_SETS) {
            set_names[n_sets] = argv[++i];
            set_values[n_sets++] = atof(argv[++i]);
        } else if (argv[i][0] != '-' && !fmu_path)
            fmu_path = argv[i];
        else {
            usage();
            return 2;
        }
    }
    if (!fmu_path || !(step > 0.0) || !(stop >= 0.0)) {
        usage();
        return 2;
    }
    if (!mkdtemp(folder)) {
        perror("mkdtemp");
        return 1;
    }

    callbacks.malloc = malloc;
    callbacks.calloc = calloc;
    callbacks.realloc = realloc;
    callbacks.free = free;
    callbacks.logger = library_logger;
    callbacks.log_level = jm_log_level_warning;
    callbacks.context = NULL;

    context = fmi_import_allocate_context(&callbacks);
    if (!context || fmi_import_get_fmi_version(context, fmu_path, folder) != fmi_version_3_0_enu) {
        error_lines++;
        printf("[HOST Error] %s: not an FMI 3.0 FMU, or it cannot be unpacked\n", fmu_path);
        goto done;
    }
    fmu = fmi3_import_parse_xml(context, folder, NULL);
    if (!fmu) {
        error_lines++;
        printf("[HOST Error] the model description cannot be parsed\n");
        goto done;
    }
    if (!(fmi3_import_get_fmu_kind(fmu) & fmi3_fmu_kind_cs)) {
        error_lines++;
        printf("[HOST Error] the FMU has no co-simulation interface\n");
        goto done;
    }
    if (fmi3_import_create_dllfmu(fmu, fmi3_fmu_kind_cs, NULL, fmu_logger) != jm_status_success) {
        error_lines++;
        printf("[HOST Error] the binary cannot be loaded: %s\n", fmi3_import_get_last_error(fmu));
        goto done;
    }
    dll = 1;

    variables = fmi3_import_get_variable_list(fmu, 0);
    n = fmi3_import_get_variable_list_size(variables);
    o.vr_float64 = calloc(n + 1, sizeof *o.vr_float64);
    o.vr_int32 = calloc(n + 1, sizeof *o.vr_int32);
    o.vr_int64 = calloc(n + 1, sizeof *o.vr_int64);
    o.vr_boolean = calloc(n + 1, sizeof *o.vr_boolean);
    o.name_float64 = calloc(n + 1, sizeof *o.name_float64);
    o.name_int32 = calloc(n + 1, sizeof *o.name_int32);
    o.name_int64 = calloc(n + 1, sizeof *o.name_int64);
    o.name_boolean = calloc(n + 1, sizeof *o.name_boolean);
    o.float64 = calloc(n + 1, sizeof *o.float64);
    o.int32 = calloc(n + 1, sizeof *o.int32);
    o.int64 = calloc(n + 1, sizeof *o.int64);
    o.boolean = calloc(n + 1, sizeof *o.boolean);
    for (k = 0; k < n; k++) {
        fmi3_import_variable_t *v = fmi3_import_get_variable(variables, k);
        if (fmi3_import_get_variable_causality(v) == fmi3_causality_enu_output)
            add_output(&o, v);
    }

    if (fmi3_import_instantiate_co_simulation(fmu, "fmil3_host", NULL, fmi3_false, fmi3_true,
                                              event_mode ? fmi3_true : fmi3_false,
                                              event_mode ? fmi3_true : fmi3_false, NULL, 0,
                                              NULL) != jm_status_success) {
        error_lines++;
        printf("[HOST Error] fmi3InstantiateCoSimulation returned NULL\n");
        goto done;
    }
    instantiated = 1;

    for (i = 0; i < n_sets; i++) {
        fmi3_import_variable_t *v = fmi3_import_get_variable_by_name(fmu, set_names[i]);
        fmi3_value_reference_t vr;
        if (!v || fmi3_import_get_variable_base_type(v) != fmi3_base_type_float64) {
            error_lines++;
            printf("[HOST Error] --set %s: no Float64 variable of that name\n", set_names[i]);
            goto done;
        }
        vr = fmi3_import_get_variable_vr(v);
        if (checked(fmi3_import_set_float64(fmu, &vr, 1, &set_values[i], 1), "fmi3SetFloat64"))
            goto done;
    }

    if (checked(fmi3_import_enter_initialization_mode(fmu, fmi3_false, 0.0, 0.0, fmi3_true, stop),
                "fmi3EnterInitializationMode")
        || checked(fmi3_import_exit_initialization_mode(fmu), "fmi3ExitInitializationMode"))
        goto done;
    /* with event mode used, the instance is in Event Mode after initialization */
    if (event_mode) {
        fmi3_boolean_t update = fmi3_true, terminate, nominals, values, defined;
        fmi3_float64_t next;
        while (update)
            if (checked(fmi3_import_update_discrete_states(fmu, &update, &terminate, &nominals,
                                                           &values, &defined, &next),
                        "fmi3UpdateDiscreteStates"))
                goto done;
        if (checked(fmi3_import_enter_step_mode(fmu), "fmi3EnterStepMode"))
            goto done;
    }

    if (output_path) {
        out = fopen(output_path, "w");
        if (!out) {
            error_lines++;
            printf("[HOST Error] %s cannot be written\n", output_path);
            goto done;
        }
        write_header(out, &o);
    }
    if (read_outputs(fmu, &o))
        goto done;
    if (out)
        write_row(out, time, &o);

    while (time < stop - 0.5 * step) {
        fmi3_boolean_t event = fmi3_false, terminate = fmi3_false, early = fmi3_false;
        fmi3_float64_t reached = time;
        double h = (stop - time < 1.5 * step) ? stop - time : step;
        if (checked(fmi3_import_do_step(fmu, time, h, fmi3_true, &event, &terminate, &early,
                                        &reached), "fmi3DoStep"))
            goto done;
        steps++;
        time = early ? reached : time + h;
        if (early)
            early_returns++;
        if (read_outputs(fmu, &o))
            goto done;
        if (out)
            write_row(out, time, &o);
        if (terminate) {
            printf("[HOST] the FMU asks to terminate at %.17g s\n", time);
            break;
        }
        if (event && event_mode) {
            events++;
            if (handle_event(fmu))
                goto done;
        }
    }

    if (checked(fmi3_import_terminate(fmu), "fmi3Terminate"))
        goto done;
    failed = 0;

done:
    if (out)
        fclose(out);
    if (instantiated)
        fmi3_import_free_instance(fmu);
    if (variables)
        fmi3_import_free_variable_list(variables);
    if (dll)
        fmi3_import_destroy_dllfmu(fmu);
    printf("fmil3_host: %s: %ld steps to %.17g s, %ld event(s), %ld early return(s), "
           "%d warning line(s), %d error line(s) (%d from the FMI Library)\n",
           fmu ? fmi3_import_get_model_name(fmu) : fmu_path, steps, time, events, early_returns,
           warning_lines, error_lines, library_error_lines);
    if (fmu)
        fmi3_import_free(fmu);
    if (context)
        fmi_import_free_context(context);
    fmi_import_rmdir(&callbacks, folder);
    free(o.vr_float64); free(o.vr_int32); free(o.vr_int64); free(o.vr_boolean);
    free(o.name_float64); free(o.name_int32); free(o.name_int64); free(o.name_boolean);
    free(o.float64); free(o.int32); free(o.int64); free(o.boolean);
    return (failed || error_lines) ? 1 : 0;
}
