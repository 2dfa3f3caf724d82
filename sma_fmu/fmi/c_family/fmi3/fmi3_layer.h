/* The FMI 3.0 co-simulation front of the native models (private header): fmi3Functions.h
 * over the version-neutral core (core/layer.h), as the FMI 2.0 front is. Every function
 * names itself ("fmi3DoStep") in its messages; no call goes through an fmi2 function. */
#ifndef SMA_FMI3_LAYER_H
#define SMA_FMI3_LAYER_H

#include "fmi3Functions.h"
#include "layer.h"

#define ENTER                                                                                 \
    Instance *in = layer_instance(instance, __func__);                                        \
    if (!in) return fmi3Error
#define DONE(status) return (fmi3Status)(status)

/* fmi3_variables.c: the value reference of the independent variable `time` (one past the
 * model's variables: the core's table keeps the FMI 2.0 numbering). */
unsigned int fmi3_time_vr(void);

#endif
