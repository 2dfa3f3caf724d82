/* fmi2Get/Set/FreeFMUstate and their serialization: the FMI 2.0 front over the core's saved
 * states (core/layer_states.c), which check and restore them. */
#include "fp_contract.h"
#include <stdio.h>

#include "fmi2_layer.h"

FMI2_Export fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state)
{
    ENTER;
    return (fmi2Status)layer_get_state(in, "fmi2GetFMUstate", state);
}

FMI2_Export fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state)
{
    ENTER;
    return (fmi2Status)layer_set_state(in, "fmi2SetFMUstate", state);
}

FMI2_Export fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state)
{
    ENTER;
    return (fmi2Status)layer_free_state(in, "fmi2FreeFMUstate", state);
}

FMI2_Export fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t *size)
{
    SavedState *saved;
    ENTER;
    saved = state ? layer_find_state(in, state) : NULL;
    if (!saved || !size)
        return (fmi2Status)layer_reject(in, SMA_ERROR, "fmi2SerializedFMUstateSize", "FMUstate is "
                                        "not a state of this instance, or size is NULL");
    *size = saved->size;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state,
                                             fmi2Byte serializedState[], size_t size)
{
    ENTER;
    return (fmi2Status)layer_serialize_state(in, "fmi2SerializeFMUstate", state,
                                             (unsigned char *)serializedState, size);
}

FMI2_Export fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[],
                                               size_t size, fmi2FMUstate *state)
{
    ENTER;
    return (fmi2Status)layer_deserialize_state(in, "fmi2DeSerializeFMUstate",
                                               (const unsigned char *)serializedState, size, state);
}
