/* fmi3Get/fmi3Set: FMI 3.0's typed accessors over the core's (core/layer_variables.c).
 *
 * The core keeps FMI 2.0's variables and rules; here they take FMI 3.0's types: Real is
 * Float64, Integer Int32, a choice parameter (hysteresis_mode, inverse) an Enumeration read
 * and set as Int64, Boolean is bool. The plant's structural parameter memory_depth and its
 * reversal_count are UInt64 (fmi3_structural.c), its reversal arrays Float64 outputs of
 * memory_depth values each (fmi3_arrays.c): nValues counts array elements, and must
 * equal nValueReferences where all are scalars (another size: fmi3Error naming the arrays,
 * nothing read or set). In Configuration Mode only the structural parameter may be set. The
 * independent variable `time` (fmi3_time_vr) reads as the present communication point and
 * cannot be set. Types this FMU has no variables of refuse every value reference, naming
 * what it is. */
#include "fp_contract.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3_layer.h"
#include "fmi3_model.h"   /* generated: TIME_VR, ENUMERATIONS, the arrays */

unsigned int fmi3_time_vr(void) { return TIME_VR; }

static const unsigned int ARRAY_VR_LIST[] = ARRAY_VRS;
static const char *const ARRAY_NAME_LIST[] = ARRAY_NAMES;

static int is_enumeration(unsigned int vr)
{
    static const unsigned int enumerations[] = ENUMERATIONS;
    size_t i;
    for (i = 0; i < sizeof enumerations / sizeof enumerations[0]; ++i)
        if (enumerations[i] == vr && vr != TIME_VR) return 1;
    return 0;
}

static int has_arrays(const Instance *in, const fmi3ValueReference vr[], size_t nvr)
{
    size_t i;
    for (i = 0; i < nvr; ++i)
        if (fmi3_array_of(in, ARRAY_VR_LIST, vr[i]) < in->model->array_count) return 1;
    return 0;
}

const char *fmi3_type_of(const Instance *in, unsigned int vr, const char **name)
{
    static const char *const TYPES[] = {"Float64", "Int32", "Boolean", "String"};
    const SmaVariable *v = layer_variable(in->model, vr, NULL);
    size_t k = fmi3_array_of(in, ARRAY_VR_LIST, vr);
    if (vr == TIME_VR) { *name = "time"; return "Float64"; }
    if (k < in->model->array_count) { *name = ARRAY_NAME_LIST[k]; return "Float64"; }
    if (vr == STRUCTURAL_VR) { *name = v ? v->name : "?"; return "UInt64"; }
    if (vr == COUNT_VR) { *name = COUNT_NAME; return "UInt64"; }
    if (!v) return NULL;
    *name = v->name;
    return v->kind == SMA_INTEGER && is_enumeration(vr) ? "Enumeration" : TYPES[v->kind];
}

/* The shared argument checks; 0: nothing to do (*status says how it ended). */
static int arguments_ok(Instance *in, const char *function, const fmi3ValueReference vr[],
                        size_t nvr, const void *values, size_t nValues, SmaStatus *status)
{
    char why[200];
    if (!layer_arrays_ok(in, function, vr, nvr, values, status)) return 0;
    if (nValues != nvr && !(values && has_arrays(in, vr, nvr))) {
        snprintf(why, sizeof why, "nValues = %lu, but the %lu value references are scalars "
                 "and take %lu values; nothing was done", (unsigned long)nValues,
                 (unsigned long)nvr, (unsigned long)nvr);
        *status = layer_reject(in, SMA_ERROR, function, why);
        return 0;
    }
    return 1;
}

int fmi3_configuring(Instance *in, const char *function)
{
    char why[200];
    const char *name = "?";
    if (!in->configuration_mode) return 0;
    fmi3_type_of(in, STRUCTURAL_VR, &name);
    snprintf(why, sizeof why, "in Configuration Mode only the structural parameter %s can be "
             "set; nothing was set", name);
    layer_refuse(in, SMA_ERROR, function, why);
    return 1;
}

/* Refuses the first value reference that is not of FMI 3.0 type `type` (0), or 1. */
int fmi3_all_of_type(Instance *in, const char *function, const char *type,
                       const fmi3ValueReference vr[], size_t nvr)
{
    char why[300];
    size_t i;
    for (i = 0; i < nvr; ++i) {
        const char *name = NULL, *found = fmi3_type_of(in, vr[i], &name);
        if (found && strcmp(found, type) == 0) continue;
        if (!found)
            snprintf(why, sizeof why, "value reference %u is not a variable of %s; nothing was "
                     "done", vr[i], in->model->name);
        else
            snprintf(why, sizeof why, "value reference %u is %s variable %s, not %s %s; nothing "
                     "was done", vr[i], found, name, strchr("AEIOU", type[0]) ? "an" : "a", type);
        layer_refuse(in, SMA_ERROR, function, why);
        return 0;
    }
    return 1;
}

static int has_time(const fmi3ValueReference vr[], size_t nvr)
{
    size_t i;
    for (i = 0; i < nvr; ++i)
        if (vr[i] == TIME_VR) return 1;
    return 0;
}

FMI3_Export fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[],
                                      size_t nvr, fmi3Float64 values[], size_t nValues)
{
    const char *function = "fmi3GetFloat64";
    SmaStatus status;
    size_t i;
    ENTER;
    if (!arguments_ok(in, function, vr, nvr, values, nValues, &status)) DONE(status);
    if (has_arrays(in, vr, nvr))
        DONE(layer_finish(in, fmi3_get_arrays(in, function, vr, nvr, values, nValues,
                                               ARRAY_VR_LIST, ARRAY_NAME_LIST, TIME_VR,
                                               in->time_defined ? in->time : in->run.start_time)));
    if (!has_time(vr, nvr)) DONE(layer_finish(in, layer_get(in, function, SMA_REAL, vr, nvr, values)));
    for (i = 0; i < nvr; ++i) {  /* with time: one by one (rare) */
        if (vr[i] == TIME_VR) values[i] = in->time_defined ? in->time : in->run.start_time;
        else if (layer_get(in, function, SMA_REAL, &vr[i], 1, &values[i]) != SMA_OK)
            DONE(layer_finish(in, SMA_ERROR));
    }
    DONE(layer_finish(in, SMA_OK));
}

FMI3_Export fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[],
                                      size_t nvr, const fmi3Float64 values[], size_t nValues)
{
    const char *function = "fmi3SetFloat64";
    SmaStatus status;
    ENTER;
    if (!arguments_ok(in, function, vr, nvr, values, nValues, &status)) DONE(status);
    if (has_time(vr, nvr))
        DONE(layer_refuse(in, SMA_ERROR, function, "time cannot be set: it is the independent "
                          "variable; nothing was set"));
    if (has_arrays(in, vr, nvr)) {
        size_t i;
        char why[300];
        for (i = 0; fmi3_array_of(in, ARRAY_VR_LIST, vr[i]) >= in->model->array_count; ++i) {}
        snprintf(why, sizeof why, "%s (value reference %u) cannot be set: it is an output; "
                 "only inputs and parameters can be set; nothing was set",
                 ARRAY_NAME_LIST[fmi3_array_of(in, ARRAY_VR_LIST, vr[i])], vr[i]);
        DONE(layer_refuse(in, SMA_ERROR, function, why));
    }
    if (fmi3_configuring(in, function)) DONE(SMA_ERROR);
    DONE(layer_finish(in, layer_set(in, function, SMA_REAL, vr, nvr, values)));
}

/* Int32, Int64 (Enumerations) and Boolean pass through the core's int values. */
static SmaStatus get_ints(Instance *in, const char *function, const char *type, SmaKind kind,
                          const fmi3ValueReference vr[], size_t nvr, void *values, size_t nValues)
{
    SmaStatus status;
    size_t i;
    int *buffer;
    if (!arguments_ok(in, function, vr, nvr, values, nValues, &status)) return status;
    if (!fmi3_all_of_type(in, function, type, vr, nvr)) return SMA_ERROR;
    buffer = (int *)malloc(nvr * sizeof *buffer);
    if (!buffer) return layer_refuse(in, SMA_ERROR, function, "out of memory");
    status = layer_get(in, function, kind, vr, nvr, buffer);
    for (i = 0; i < nvr; ++i) {
        if (type[0] == 'I') ((fmi3Int32 *)values)[i] = (fmi3Int32)buffer[i];
        else if (type[0] == 'E') ((fmi3Int64 *)values)[i] = (fmi3Int64)buffer[i];
        else ((fmi3Boolean *)values)[i] = buffer[i] != 0;
    }
    free(buffer);
    return layer_finish(in, status);
}

static SmaStatus set_ints(Instance *in, const char *function, const char *type, SmaKind kind,
                          const fmi3ValueReference vr[], size_t nvr, const void *values,
                          size_t nValues)
{
    char why[300];
    SmaStatus status;
    size_t i;
    int *buffer;
    if (!arguments_ok(in, function, vr, nvr, values, nValues, &status)) return status;
    if (!fmi3_all_of_type(in, function, type, vr, nvr) || fmi3_configuring(in, function))
        return SMA_ERROR;
    buffer = (int *)malloc(nvr * sizeof *buffer);
    if (!buffer) return layer_refuse(in, SMA_ERROR, function, "out of memory");
    for (i = 0; i < nvr; ++i) {
        if (type[0] == 'I') buffer[i] = (int)((const fmi3Int32 *)values)[i];
        else if (type[0] == 'B') buffer[i] = ((const fmi3Boolean *)values)[i] ? 1 : 0;
        else {
            fmi3Int64 value = ((const fmi3Int64 *)values)[i];
            if (value < -2147483647 - 1 || value > 2147483647) {
                const char *name = "?";
                fmi3_type_of(in, vr[i], &name);
                snprintf(why, sizeof why, "%s (value reference %u) cannot be set: %lld is no "
                         "item of the Enumeration; nothing was set", name, vr[i], (long long)value);
                free(buffer);
                return layer_refuse(in, SMA_ERROR, function, why);
            }
            buffer[i] = (int)value;
        }
    }
    status = layer_set(in, function, kind, vr, nvr, buffer);
    free(buffer);
    return layer_finish(in, status);
}

FMI3_Export fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference vr[],
                                    size_t nvr, fmi3Int32 values[], size_t nValues)
{
    ENTER;
    DONE(get_ints(in, "fmi3GetInt32", "Int32", SMA_INTEGER, vr, nvr, values, nValues));
}

FMI3_Export fmi3Status fmi3SetInt32(fmi3Instance instance, const fmi3ValueReference vr[],
                                    size_t nvr, const fmi3Int32 values[], size_t nValues)
{
    ENTER;
    DONE(set_ints(in, "fmi3SetInt32", "Int32", SMA_INTEGER, vr, nvr, values, nValues));
}

FMI3_Export fmi3Status fmi3GetInt64(fmi3Instance instance, const fmi3ValueReference vr[],
                                    size_t nvr, fmi3Int64 values[], size_t nValues)
{
    ENTER;
    DONE(get_ints(in, "fmi3GetInt64", "Enumeration", SMA_INTEGER, vr, nvr, values, nValues));
}

FMI3_Export fmi3Status fmi3SetInt64(fmi3Instance instance, const fmi3ValueReference vr[],
                                    size_t nvr, const fmi3Int64 values[], size_t nValues)
{
    ENTER;
    DONE(set_ints(in, "fmi3SetInt64", "Enumeration", SMA_INTEGER, vr, nvr, values, nValues));
}

FMI3_Export fmi3Status fmi3GetBoolean(fmi3Instance instance, const fmi3ValueReference vr[],
                                      size_t nvr, fmi3Boolean values[], size_t nValues)
{
    ENTER;
    DONE(get_ints(in, "fmi3GetBoolean", "Boolean", SMA_BOOLEAN, vr, nvr, values, nValues));
}

FMI3_Export fmi3Status fmi3SetBoolean(fmi3Instance instance, const fmi3ValueReference vr[],
                                      size_t nvr, const fmi3Boolean values[], size_t nValues)
{
    ENTER;
    DONE(set_ints(in, "fmi3SetBoolean", "Boolean", SMA_BOOLEAN, vr, nvr, values, nValues));
}

FMI3_Export fmi3Status fmi3GetString(fmi3Instance instance, const fmi3ValueReference vr[],
                                     size_t nvr, fmi3String values[], size_t nValues)
{
    SmaStatus status;
    ENTER;
    if (!arguments_ok(in, "fmi3GetString", vr, nvr, values, nValues, &status)) DONE(status);
    DONE(layer_finish(in, layer_get(in, "fmi3GetString", SMA_STRING, vr, nvr, values)));
}

FMI3_Export fmi3Status fmi3SetString(fmi3Instance instance, const fmi3ValueReference vr[],
                                     size_t nvr, const fmi3String values[], size_t nValues)
{
    SmaStatus status;
    size_t i;
    ENTER;
    if (!arguments_ok(in, "fmi3SetString", vr, nvr, values, nValues, &status)) DONE(status);
    if (fmi3_configuring(in, "fmi3SetString")) DONE(SMA_ERROR);
    for (i = 0; i < nvr; ++i) {
        if (!values[i] || !layer_valid_utf8(values[i])) {
            layer_plain(in, SMA_ERROR, "fmi3SetString: values[%lu] for value reference %u is %s; "
                        "nothing was set", (unsigned long)i, vr[i], values[i] ? "not UTF-8" : "NULL");
            return fmi3Error;
        }
    }
    DONE(layer_finish(in, layer_set(in, "fmi3SetString", SMA_STRING, vr, nvr, values)));
}

/* A type no variable of this FMU has: nothing to get or set, every reference refused. */
static SmaStatus no_such_type(Instance *in, const char *function, const char *type,
                              const fmi3ValueReference vr[], size_t nvr, const void *values)
{
    SmaStatus status;
    if (!layer_arrays_ok(in, function, vr, nvr, values, &status)) return status;
    fmi3_all_of_type(in, function, type, vr, nvr);
    return SMA_ERROR;
}

#define NO_SUCH_TYPE(T)                                                                       \
    FMI3_Export fmi3Status fmi3Get##T(fmi3Instance instance, const fmi3ValueReference vr[],   \
                                      size_t nvr, fmi3##T values[], size_t nValues)           \
    {                                                                                         \
        ENTER;                                                                                \
        (void)nValues;                                                                        \
        DONE(no_such_type(in, "fmi3Get" #T, #T, vr, nvr, values));                            \
    }                                                                                         \
    FMI3_Export fmi3Status fmi3Set##T(fmi3Instance instance, const fmi3ValueReference vr[],   \
                                      size_t nvr, const fmi3##T values[], size_t nValues)     \
    {                                                                                         \
        ENTER;                                                                                \
        (void)nValues;                                                                        \
        DONE(no_such_type(in, "fmi3Set" #T, #T, vr, nvr, values));                            \
    }
NO_SUCH_TYPE(Float32)
NO_SUCH_TYPE(Int8)
NO_SUCH_TYPE(UInt8)
NO_SUCH_TYPE(Int16)
NO_SUCH_TYPE(UInt16)
NO_SUCH_TYPE(UInt32)

FMI3_Export fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference vr[],
                                     size_t nvr, size_t valueSizes[], fmi3Binary values[],
                                     size_t nValues)
{
    ENTER;
    (void)valueSizes; (void)nValues;
    DONE(no_such_type(in, "fmi3GetBinary", "Binary", vr, nvr, values));
}

FMI3_Export fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference vr[],
                                     size_t nvr, const size_t valueSizes[],
                                     const fmi3Binary values[], size_t nValues)
{
    ENTER;
    (void)valueSizes; (void)nValues;
    DONE(no_such_type(in, "fmi3SetBinary", "Binary", vr, nvr, values));
}

FMI3_Export fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference vr[],
                                    size_t nvr, fmi3Clock values[])
{
    ENTER;
    DONE(no_such_type(in, "fmi3GetClock", "Clock", vr, nvr, values));
}

FMI3_Export fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference vr[],
                                    size_t nvr, const fmi3Clock values[])
{
    ENTER;
    DONE(no_such_type(in, "fmi3SetClock", "Clock", vr, nvr, values));
}
