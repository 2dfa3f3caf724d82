/* Packed start values: resources/start_values.json, which `sma-fmu export` writes into every
 * FMU it packs (slave_support/start_values.py). */
#include <stdio.h>

#include "fmi2_layer.h"

int layer_packed_start_values(Instance *in, char *why, size_t size)
{
    (void)in; (void)why; (void)size;
    return 0;
}
