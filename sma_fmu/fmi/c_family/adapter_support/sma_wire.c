/* The wire parameters of an instance (sma_wire.h). */
#include "fp_contract.h"
#include <math.h>
#include <stdio.h>

#include "sma_wire.h"

/* May the parameter `index` be not given (NaN in its variable)? The optional ones without a
 * number as default (alpha and the model terms; wire_use.NULLABLE): memory_depth and
 * stress_max have one, so a NaN there is a value, refused by its rule. */
static int nullable(int index)
{
    if (PARAMETER_SPECS[index].required) return 0;
#define SMA_HAS_DEFAULT(name, number) if (index == PARAM_##name) return 0;
    SMA_PARAMETER_DEFAULTS(SMA_HAS_DEFAULT)
#undef SMA_HAS_DEFAULT
    return 1;
}

int sma_wire_parameters(const SmaModel *model, const SmaValue *values, const SmaRun *run,
                        WireParameters *out, SmaMessage *message)
{
    double merged[PARAM_COUNT];
    unsigned char given[PARAM_COUNT];
    char source[256];
    size_t i;
    if (run->wire_defaults == NULL || run->wire_count != PARAM_COUNT)
        return sma_message_set(message, "model_starts.json: %lu wire parameters, not %d",
                               (unsigned long)run->wire_count, (int)PARAM_COUNT);
    for (i = 0; i < PARAM_COUNT; ++i) {  /* a default NaN: an optional parameter not given */
        merged[i] = run->wire_defaults[i];
        given[i] = !isnan(merged[i]);
    }
    for (i = 0; i < model->count; ++i) {  /* a variable is given, NaN too, but where NaN
                                             * means "not given" (SlaveInterface.wire_parameters) */
        const SmaVariable *v = &model->variables[i];
        if (v->wire >= 0 && v->wire < PARAM_COUNT) {
            merged[v->wire] = v->kind == SMA_REAL ? values[i].real : (double)values[i].integer;
            given[v->wire] = !(isnan(merged[v->wire]) && nullable(v->wire));
        }
    }
    snprintf(source, sizeof source, "%s instance '%s'", run->model_name, run->instance_name);
    return wire_parameters_from_given(out, merged, given, source, message);
}
