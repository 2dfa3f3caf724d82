/* The FMI 2.0 front of the native models (private header): fmi2Functions.h over the
 * version-neutral core (core/layer.h). The front translates types and names its own
 * functions; the core does the rest. Statuses share their numbering (SmaStatus). */
#ifndef SMA_FMI2_LAYER_H
#define SMA_FMI2_LAYER_H

#include "fmi2Functions.h"
#include "layer.h"

#define ENTER                                                                                 \
    Instance *in = layer_instance(c, __func__);                                               \
    if (!in) return fmi2Error

#endif
