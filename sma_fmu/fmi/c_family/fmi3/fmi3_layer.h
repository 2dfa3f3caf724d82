/* The FMI 3.0 co-simulation front of the native models (private header): fmi3Functions.h
 * over the version-neutral core (core/layer.h), as the FMI 2.0 front is. Every function
 * names itself ("fmi3DoStep") in its messages; no call goes through an fmi2 function. */
#ifndef SMA_FMI3_LAYER_H
#define SMA_FMI3_LAYER_H

/* The standard's fmi3FunctionTypes.h declares two callbacks with "()" (no prototype), which
 * clang's -Wpedantic -Werror (zig cc: the macOS and aarch64 builds) refuses; the standard's
 * headers are kept as published, so that one warning is silenced around them alone. */
#if defined(__clang__)
#pragma clang diagnostic push
#pragma clang diagnostic ignored "-Wstrict-prototypes"
#endif
#include "fmi3Functions.h"
#if defined(__clang__)
#pragma clang diagnostic pop
#endif
#include "layer.h"

#define ENTER                                                                                 \
    Instance *in = layer_instance(instance, __func__);                                        \
    if (!in) return fmi3Error
#define DONE(status) return (fmi3Status)(status)

/* fmi3_variables.c: the value reference of the independent variable `time` (one past the
 * model's variables: the core's table keeps the FMI 2.0 numbering). */
unsigned int fmi3_time_vr(void);
/* The FMI 3.0 type of the variable at `vr` ("Float64", "Enumeration", "UInt64", ...) and its
 * name in *name, or NULL: no variable. */
const char *fmi3_type_of(const Instance *in, unsigned int vr, const char **name);
/* Refuses the first value reference that is not of FMI 3.0 type `type` (0), or 1. */
int fmi3_all_of_type(Instance *in, const char *function, const char *type,
                     const fmi3ValueReference vr[], size_t nvr);
/* 1 (refused, logged) if the instance is in Configuration Mode, where only the structural
 * parameter may be set; else 0. */
int fmi3_configuring(Instance *in, const char *function);

/* fmi3_arrays.c: the model's arrays (the model contract's get_array) for fmi3GetFloat64. */
/* array_vrs[k] is the value reference of the model's array k, array_names[k] its name (both
 * from the FMI 3.0 description). */
size_t fmi3_array_of(const Instance *in, const unsigned int array_vrs[], unsigned int vr);
size_t fmi3_array_length(const Instance *in);   /* elements per array (0: no arrays) */
/* A Float64 get whose nValues counts array elements (values[], nValues, index); a wrong
 * nValues is refused before anything is read, naming the arrays and their length. */
SmaStatus fmi3_get_arrays(Instance *in, const char *function, const unsigned int vr[],
                           size_t nvr, double values[], size_t nValues,
                           const unsigned int array_vrs[], const char *const array_names[],
                           unsigned int time_vr, double time);

#endif
