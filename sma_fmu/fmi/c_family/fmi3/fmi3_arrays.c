/* A model's array outputs (FMI 3.0 only: FMI 2.0 declares no arrays): a get whose values
 * count array elements, over the model contract's get_array (core/sma_model.h).
 *
 * As in the Reference-FMUs, `values` holds nValues elements and `index` advances through
 * them: a scalar takes one, an array the length its size parameter has now (the model's
 * `array_size` variable, memory_depth for the plant). The sizes are added up first, so a
 * wrong nValues reads nothing and is refused naming the arrays and their lengths; only then
 * is each value written, the scalars by the core's get (layer_get), the arrays by the
 * model's get_array, the independent variable (`time_vr`, FMI 3.0's time) as `time` [s]. */
#include "fp_contract.h"
#include <stdio.h>

#include "fmi3_layer.h"

/* The model's array number of `vr`, or array_count if it is none. */
size_t fmi3_array_of(const Instance *in, const unsigned int array_vrs[], unsigned int vr)
{
    size_t k, count = in->model->array_count;
    for (k = 0; k < count; ++k)
        if (array_vrs[k] == vr) return k;
    return count;
}

size_t fmi3_array_length(const Instance *in)
{
    return in->model->array_count ? (size_t)in->values[in->model->array_size].integer : 0;
}

/* "nValues = .., but the value references take .. values (name: an array of n, ...)". */
static SmaStatus wrong_size(Instance *in, const char *function, const unsigned int vr[],
                            size_t nvr, size_t nValues, size_t needed,
                            const unsigned int array_vrs[], const char *const array_names[])
{
    char text[700];
    size_t i, used, count = in->model->array_count, length = fmi3_array_length(in);
    used = (size_t)snprintf(text, sizeof text, "nValues = %lu, but the %lu value references "
                            "take %lu values", (unsigned long)nValues, (unsigned long)nvr,
                            (unsigned long)needed);
    for (i = 0; i < nvr && used < sizeof text; ++i) {
        size_t k = fmi3_array_of(in, array_vrs, vr[i]);
        if (k < count)
            used += (size_t)snprintf(text + used, sizeof text - used, "; %s is an array of %lu "
                                     "(its length is %s)", array_names[k], (unsigned long)length,
                                     in->model->variables[in->model->array_size].name);
    }
    if (used < sizeof text) snprintf(text + used, sizeof text - used, "; nothing was done");
    return layer_reject(in, SMA_ERROR, function, text);
}

SmaStatus fmi3_get_arrays(Instance *in, const char *function, const unsigned int vr[],
                           size_t nvr, double values[], size_t nValues,
                           const unsigned int array_vrs[], const char *const array_names[],
                           unsigned int time_vr, double time)
{
    size_t i, index = 0, needed = 0, count = in->model->array_count;
    size_t length = fmi3_array_length(in);
    for (i = 0; i < nvr; ++i)
        needed += fmi3_array_of(in, array_vrs, vr[i]) < count ? length : 1;
    if (needed != nValues)
        return wrong_size(in, function, vr, nvr, nValues, needed, array_vrs, array_names);
    if (in->state == STATE_INSTANTIATED)
        return layer_refuse(in, SMA_ERROR, function, "illegal call in state 'instantiated'");
    if (in->state == STATE_INITIALIZATION && !layer_refresh_outputs(in, function))
        return SMA_ERROR;
    if (!in->stepper)
        return layer_refuse(in, SMA_ERROR, function, "the arrays are undefined: the model "
                            "was not started");
    for (i = 0; i < nvr; ++i) {
        size_t k = fmi3_array_of(in, array_vrs, vr[i]);
        if (k < count) {
            if (in->model->get_array(in->stepper, in->values, k, values, nValues, &index))
                return layer_refuse(in, SMA_ERROR, function, "an array does not fit");
        } else if (vr[i] == time_vr) {
            values[index++] = time;
        } else if (layer_get(in, function, SMA_REAL, &vr[i], 1, &values[index++]) != SMA_OK) {
            return SMA_ERROR;
        }
    }
    return SMA_OK;
}
