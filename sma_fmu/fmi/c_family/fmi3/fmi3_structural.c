/* The plant's structural parameter and Configuration Mode (FMI 3.0).
 *
 * SmaActuator's memory_depth [1] (the most reversal points its minor-loop memory keeps, as
 * in FMI 2.0) is a UInt64 structural parameter: it sets the length of the reversal arrays
 * and, as in FMI 2.0, the depth of the stack. It can be set only in Configuration Mode
 * (fmi3EnterConfigurationMode from the Instantiated state, fmi3ExitConfigurationMode back),
 * within [STRUCTURAL_MIN, STRUCTURAL_MAX] (the runtime's bounds); anything else gets
 * fmi3Error naming it, nothing set. reversal_count [1], the entries of the stack in use, is
 * a UInt64 output read like the other outputs. A model without a structural parameter
 * refuses Configuration Mode and every UInt64 value reference. */
#include "fp_contract.h"
#include <stdio.h>

#include "fmi3_layer.h"
#include "fmi3_model.h"   /* generated: STRUCTURAL_VR, COUNT_VR, their bounds */

#define HAS_STRUCTURAL (STRUCTURAL_VR != TIME_VR)

FMI3_Export fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance)
{
    const char *function = "fmi3EnterConfigurationMode";
    ENTER;
    if (!HAS_STRUCTURAL)
        DONE(layer_reject(in, SMA_ERROR, function, "not supported by this FMU (it has no "
                          "structural parameters)"));
    if (in->configuration_mode)
        DONE(layer_refuse(in, SMA_ERROR, function, "illegal call: already in Configuration Mode"));
    if (!layer_allowed(in, function, IN(STATE_INSTANTIATED))) return fmi3Error;
    in->configuration_mode = 1;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance)
{
    const char *function = "fmi3ExitConfigurationMode";
    ENTER;
    if (!HAS_STRUCTURAL)
        DONE(layer_reject(in, SMA_ERROR, function, "not supported by this FMU (it has no "
                          "structural parameters)"));
    if (!in->configuration_mode)
        DONE(layer_refuse(in, SMA_ERROR, function, "illegal call: not in Configuration Mode"));
    in->configuration_mode = 0;
    return fmi3OK;
}

/* The count output: as the other outputs, defined from Initialization Mode on. */
static SmaStatus get_count(Instance *in, const char *function, fmi3UInt64 *value)
{
    *value = 0;
    if (in->state == STATE_INSTANTIATED)
        return layer_refuse(in, SMA_ERROR, function, "illegal call in state 'instantiated'");
    if (in->state == STATE_INITIALIZATION && !layer_refresh_outputs(in, function))
        return SMA_ERROR;
    if (!in->stepper)
        return layer_refuse(in, SMA_ERROR, function, "the outputs are undefined: the model "
                            "was not started");
    *value = (fmi3UInt64)in->model->live_count(in->stepper);
    return SMA_OK;
}

FMI3_Export fmi3Status fmi3GetUInt64(fmi3Instance instance, const fmi3ValueReference vr[],
                                     size_t nvr, fmi3UInt64 values[], size_t nValues)
{
    const char *function = "fmi3GetUInt64";
    SmaStatus status;
    size_t i;
    ENTER;
    if (!layer_arrays_ok(in, function, vr, nvr, values, &status)) DONE(status);
    if (!fmi3_all_of_type(in, function, "UInt64", vr, nvr)) DONE(SMA_ERROR);
    if (nValues != nvr) {
        char why[200];
        snprintf(why, sizeof why, "nValues = %lu, but the %lu value references are scalars "
                 "and take %lu values; nothing was done", (unsigned long)nValues,
                 (unsigned long)nvr, (unsigned long)nvr);
        DONE(layer_reject(in, SMA_ERROR, function, why));
    }
    for (i = 0; i < nvr; ++i) {
        size_t index;
        if (vr[i] == COUNT_VR) {
            if (get_count(in, function, &values[i]) != SMA_OK) DONE(layer_finish(in, SMA_ERROR));
        } else {  /* the structural parameter: its value in every state */
            layer_variable(in->model, vr[i], &index);
            values[i] = (fmi3UInt64)in->values[index].integer;
        }
    }
    DONE(layer_finish(in, SMA_OK));
}

FMI3_Export fmi3Status fmi3SetUInt64(fmi3Instance instance, const fmi3ValueReference vr[],
                                     size_t nvr, const fmi3UInt64 values[], size_t nValues)
{
    const char *function = "fmi3SetUInt64";
    char why[400];
    SmaStatus status;
    const char *name = "?";
    size_t i, index;
    ENTER;
    if (!layer_arrays_ok(in, function, vr, nvr, values, &status)) DONE(status);
    if (!fmi3_all_of_type(in, function, "UInt64", vr, nvr)) DONE(SMA_ERROR);
    if (nValues != nvr) {
        snprintf(why, sizeof why, "nValues = %lu, but the %lu value references are scalars "
                 "and take %lu values; nothing was done", (unsigned long)nValues,
                 (unsigned long)nvr, (unsigned long)nvr);
        DONE(layer_reject(in, SMA_ERROR, function, why));
    }
    for (i = 0; i < nvr; ++i) {  /* all checked before anything is set */
        fmi3_type_of(in, vr[i], &name);
        if (vr[i] == COUNT_VR)
            snprintf(why, sizeof why, "%s (value reference %u) cannot be set: it is an output; "
                     "only inputs and parameters can be set; nothing was set", name, vr[i]);
        else if (!in->configuration_mode)
            snprintf(why, sizeof why, "%s (value reference %u) cannot be set: it is a structural "
                     "parameter; it can be set only in Configuration Mode (after "
                     "fmi3EnterConfigurationMode); nothing was set (value %llu)", name, vr[i],
                     (unsigned long long)values[i]);
        else if (values[i] < STRUCTURAL_MIN || values[i] > STRUCTURAL_MAX)
            snprintf(why, sizeof why, "%s (value reference %u) cannot be set: %llu is outside "
                     "[%lu, %lu]; nothing was set", name, vr[i], (unsigned long long)values[i],
                     (unsigned long)STRUCTURAL_MIN, (unsigned long)STRUCTURAL_MAX);
        else
            continue;
        DONE(layer_refuse(in, SMA_ERROR, function, why));
    }
    for (i = 0; i < nvr; ++i) {
        layer_variable(in->model, vr[i], &index);
        in->values[index].integer = (int)values[i];
    }
    return fmi3OK;
}
