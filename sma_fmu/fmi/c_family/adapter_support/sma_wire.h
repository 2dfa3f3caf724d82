/* The wire parameters of an instance: the parameter file the FMU was built with (read from
 * resources/model_starts.json into run->wire_defaults) with the present values of the
 * parameters the FMU exposes (SlaveInterface.wire_parameters): NaN in an optional one
 * without a number as default is "not given". */
#ifndef SMA_WIRE_H
#define SMA_WIRE_H

#include "parameters.h"
#include "sma_model.h"

/* Validated WireParameters, or nonzero with the ParameterError text, whose source is
 * "<model> instance '<instance>'" as in the pythonfmu FMUs. */
int sma_wire_parameters(const SmaModel *model, const SmaValue *values, const SmaRun *run,
                        WireParameters *out, SmaMessage *message);

#endif
