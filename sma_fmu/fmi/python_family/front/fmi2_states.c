/*
 * fmi2_states.c - fmi2GetFMUstate and the other state functions of the front.
 *
 * States handed to the host are FrontState wrappers kept in a list per instance, so a
 * pointer the instance never returned (or has freed) gives fmi2Error instead of reaching
 * pythonfmu as a Python object; serialized states carry a checked header (c_common/state_frame.c).
 */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "front.h"
#include "state_frame.h"  /* the frame both families put around a state (c_common) */

/* ---- saved states -------------------------------------------------------------------------- */
FrontState* find_state(Instance* in, fmi2FMUstate state)
{
    for (FrontState* s = in->states; s; s = s->next)
        if (s == (FrontState*)state) return s;
    return NULL;
}

void drop_state(Instance* in, FrontState* state)
{
    for (FrontState** link = &in->states; *link; link = &(*link)->next) {
        if (*link == state) {
            *link = state->next;
            break;
        }
    }
    if (state->saved) backend.FreeFMUstate(in->backend, &state->saved);
    free(state);
}

/* Stores `saved` in *state: in the wrapper already there, or in a new one. */
static fmi2Status hand_out_state(Instance* in, fmi2FMUstate* state, fmi2FMUstate saved)
{
    FrontState* wrapper = *state ? find_state(in, *state) : NULL;
    if (wrapper) {
        if (wrapper->saved) backend.FreeFMUstate(in->backend, &wrapper->saved);
    } else {
        wrapper = (FrontState*)calloc(1, sizeof *wrapper);
        if (!wrapper) {
            backend.FreeFMUstate(in->backend, &saved);
            return refuse(in, fmi2Error, "fmi2GetFMUstate", "out of memory");
        }
        wrapper->next = in->states;
        in->states = wrapper;
    }
    wrapper->saved = saved;
    *state = wrapper;
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate* state)
{
    ENTER(GetFMUstate);
    if (!state) return refuse(in, fmi2Error, "fmi2GetFMUstate", "FMUstate is NULL");
    if (*state && !find_state(in, *state))
        return refuse(in, fmi2Error, "fmi2GetFMUstate", "*FMUstate is neither NULL nor a state of "
                      "this instance");
    fmi2FMUstate saved = NULL;
    FORWARD(in, 0, backend.GetFMUstate(in->backend, &saved)); /* with the pending inputs */
    if (status > fmi2Warning) {
        if (saved && !in->dead) backend.FreeFMUstate(in->backend, &saved);
        return status;
    }
    fmi2Status stored = hand_out_state(in, state, saved);
    return stored > status ? stored : status;
}

EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state)
{
    ENTER(SetFMUstate);
    FrontState* wrapper = find_state(in, state);
    if (!wrapper) return refuse(in, fmi2Error, "fmi2SetFMUstate", "not a state of this instance "
                                "(NULL, freed, or made by another instance)");
    FORWARD(in, 1, backend.SetFMUstate(in->backend, wrapper->saved));
    if (status <= fmi2Warning) in->terminated = in->have_discard = 0;
    return status;
}

EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate* state)
{
    ENTER(FreeFMUstate);
    if (!state || !*state) return fmi2OK;
    FrontState* wrapper = find_state(in, *state);
    if (!wrapper) return refuse(in, fmi2Error, "fmi2FreeFMUstate", "not a state of this instance");
    drop_state(in, wrapper);
    *state = NULL;
    return fmi2OK;
}

EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t* size)
{
    ENTER(SerializedFMUstateSize);
    FrontState* wrapper = find_state(in, state);
    if (!wrapper || !size)
        return refuse(in, fmi2Error, "fmi2SerializedFMUstateSize", "unknown state or size is NULL");
    size_t payload = 0;
    fmi2Status status = finish(in, backend.SerializedFMUstateSize(in->backend, wrapper->saved, &payload));
    if (status <= fmi2Warning) *size = payload + STATE_FRAME_SIZE;
    return status;
}

EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[],
                                        size_t size)
{
    ENTER(SerializeFMUstate);
    FrontState* wrapper = find_state(in, state);
    if (!wrapper || !bytes)
        return refuse(in, fmi2Error, "fmi2SerializeFMUstate", "unknown state or bytes is NULL");
    size_t payload = 0;
    fmi2Status status = finish(in, backend.SerializedFMUstateSize(in->backend, wrapper->saved, &payload));
    if (status > fmi2Warning) return status;
    if (size != payload + STATE_FRAME_SIZE) { /* pythonfmu would copy `size` bytes unchecked */
        host_logf(in, fmi2Error, "fmi2SerializeFMUstate: size is %zu, fmi2SerializedFMUstateSize "
                  "said %zu", size, payload + STATE_FRAME_SIZE);
        return fmi2Error;
    }
    status = finish(in, backend.SerializeFMUstate(in->backend, wrapper->saved,
                                                  bytes + STATE_FRAME_SIZE, payload));
    if (status <= fmi2Warning) state_frame_write((unsigned char*)bytes, payload);
    return status;
}

EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[],
                                          size_t size, fmi2FMUstate* state)
{
    ENTER(DeSerializeFMUstate);
    if (!serializedState || !state)
        return refuse(in, fmi2Error, "fmi2DeSerializeFMUstate", "serializedState or FMUstate is NULL");
    if (*state && !find_state(in, *state))
        return refuse(in, fmi2Error, "fmi2DeSerializeFMUstate", "*FMUstate is neither NULL nor a "
                      "state of this instance");
    char why[300];
    if (!state_frame_check((const unsigned char*)serializedState, size, why, sizeof why)) {
        host_logf(in, fmi2Error, "fmi2DeSerializeFMUstate: these bytes are not a state "
                  "serialized by this FMU: %s", why);
        return fmi2Error;
    }
    fmi2FMUstate saved = NULL;
    fmi2Status status = finish(in, backend.DeSerializeFMUstate(
        in->backend, serializedState + STATE_FRAME_SIZE, size - STATE_FRAME_SIZE, &saved));
    if (status > fmi2Warning) {
        if (saved && !in->dead) backend.FreeFMUstate(in->backend, &saved);
        return status;
    }
    fmi2Status stored = hand_out_state(in, state, saved);
    return stored > status ? stored : status;
}

