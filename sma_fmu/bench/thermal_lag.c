/*
 * thermal_lag.c - a minimal native FMI 2.0 co-simulation FMU, written for `sma-fmu bench`:
 * the wire's first-order thermal lag (spec section 9, sma_fmu/runtime/thermal.py),
 *
 *     T+ = T_room + (T - T_room) e^(-h/tau) + K_th P_in (1 - e^(-h/tau)),
 *
 * with P_in held over the step. It is the floor the Python FMUs are measured against: the
 * same FMI calls with no Python behind them. Variables (value references): 0 P_in [W]
 * input, 1 T [degC] output, 2 T_room [degC], 3 K_th [K/W], 4 tau [s], 5 T_start [degC]
 * (fixed parameters). Defaults come from the build (-D), the wire's parameter file.
 * Only what a co-simulation needs is implemented; the rest returns fmi2Error.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2FunctionTypes.h"  /* the standard's FMI 2.0 types (fmi/c_common/include/) */

#ifdef _WIN32
#define EXPORT __declspec(dllexport)
#else
#define EXPORT __attribute__((visibility("default")))
#endif

#ifndef LAG_T_ROOM
#define LAG_T_ROOM 20.0
#endif
#ifndef LAG_K_TH
#define LAG_K_TH 50.0
#endif
#ifndef LAG_TAU
#define LAG_TAU 1.0
#endif

enum { P_IN, T, T_ROOM, K_TH, TAU, T_START, N_VARIABLES };

typedef struct {
    double v[N_VARIABLES];
    double decay_h, decay; /* e^(-h/tau) for the last step size h */
    int initialized;
} Lag;

EXPORT const char* fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char* fmi2GetVersion(void) { return "2.0"; }

EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid,
                                     fmi2String resources, const fmi2CallbackFunctions* callbacks,
                                     fmi2Boolean visible, fmi2Boolean loggingOn)
{
    (void)name; (void)guid; (void)resources; (void)callbacks; (void)visible; (void)loggingOn;
    if (type != fmi2CoSimulation) return NULL;
    Lag* lag = (Lag*)calloc(1, sizeof *lag);
    if (!lag) return NULL;
    lag->v[T_ROOM] = LAG_T_ROOM;
    lag->v[K_TH] = LAG_K_TH;
    lag->v[TAU] = LAG_TAU;
    lag->v[T_START] = LAG_T_ROOM;
    lag->v[T] = LAG_T_ROOM;
    lag->decay_h = -1.0;
    return lag;
}

EXPORT void fmi2FreeInstance(fmi2Component c) { free(c); }

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String k[])
{
    (void)c; (void)on; (void)n; (void)k;
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean td, fmi2Real tol, fmi2Real start,
                                      fmi2Boolean sd, fmi2Real stop)
{
    (void)c; (void)td; (void)tol; (void)start; (void)sd; (void)stop;
    return fmi2OK;
}

EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }

EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    Lag* lag = (Lag*)c;
    if (!(lag->v[TAU] > 0.0)) return fmi2Error;
    lag->v[T] = lag->v[T_START];
    lag->initialized = 1;
    return fmi2OK;
}

EXPORT fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }
EXPORT fmi2Status fmi2Reset(fmi2Component c) { (void)c; return fmi2Error; }

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[])
{
    Lag* lag = (Lag*)c;
    for (size_t i = 0; i < n; ++i) {
        if (vr[i] >= N_VARIABLES) return fmi2Error;
        value[i] = lag->v[vr[i]];
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                              const fmi2Real value[])
{
    Lag* lag = (Lag*)c;
    for (size_t i = 0; i < n; ++i) /* all or nothing; after initialization only the input */
        if (vr[i] >= N_VARIABLES || vr[i] == T || (lag->initialized && vr[i] != P_IN)) return fmi2Error;
    for (size_t i = 0; i < n; ++i) lag->v[vr[i]] = value[i];
    return fmi2OK;
}

EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_set_prior)
{
    (void)t; (void)no_set_prior;
    Lag* lag = (Lag*)c;
    if (!lag->initialized || !(h > 0.0) || !isfinite(lag->v[P_IN])) return fmi2Error;
    if (h != lag->decay_h) {
        lag->decay = exp(-h / lag->v[TAU]);
        lag->decay_h = h;
    }
    double room = lag->v[T_ROOM], d = lag->decay;
    lag->v[T] = room + (lag->v[T] - room) * d + lag->v[K_TH] * lag->v[P_IN] * (1.0 - d);
    return fmi2OK;
}

/* ---- not needed for the bench --------------------------------------------------------------- */
#define UNSUPPORTED(name, ...)                                                                  \
    EXPORT fmi2Status fmi2##name(fmi2Component c, __VA_ARGS__) { (void)c; return fmi2Error; }
UNSUPPORTED(GetInteger, const fmi2ValueReference vr[], size_t n, fmi2Integer v[])
UNSUPPORTED(GetBoolean, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[])
UNSUPPORTED(GetString, const fmi2ValueReference vr[], size_t n, fmi2String v[])
UNSUPPORTED(SetInteger, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[])
UNSUPPORTED(SetBoolean, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[])
UNSUPPORTED(SetString, const fmi2ValueReference vr[], size_t n, const fmi2String v[])
UNSUPPORTED(GetFMUstate, fmi2FMUstate* s)
UNSUPPORTED(SetFMUstate, fmi2FMUstate s)
UNSUPPORTED(FreeFMUstate, fmi2FMUstate* s)
UNSUPPORTED(SerializedFMUstateSize, fmi2FMUstate s, size_t* n)
UNSUPPORTED(SerializeFMUstate, fmi2FMUstate s, fmi2Byte b[], size_t n)
UNSUPPORTED(DeSerializeFMUstate, const fmi2Byte b[], size_t n, fmi2FMUstate* s)
UNSUPPORTED(GetDirectionalDerivative, const fmi2ValueReference u[], size_t nu,
            const fmi2ValueReference z[], size_t nz, const fmi2Real dz[], fmi2Real du[])
UNSUPPORTED(SetRealInputDerivatives, const fmi2ValueReference vr[], size_t n,
            const fmi2Integer order[], const fmi2Real v[])
UNSUPPORTED(GetRealOutputDerivatives, const fmi2ValueReference vr[], size_t n,
            const fmi2Integer order[], fmi2Real v[])
EXPORT fmi2Status fmi2CancelStep(fmi2Component c) { (void)c; return fmi2Error; }
UNSUPPORTED(GetStatus, const fmi2StatusKind s, fmi2Status* v)
UNSUPPORTED(GetRealStatus, const fmi2StatusKind s, fmi2Real* v)
UNSUPPORTED(GetIntegerStatus, const fmi2StatusKind s, fmi2Integer* v)
UNSUPPORTED(GetBooleanStatus, const fmi2StatusKind s, fmi2Boolean* v)
UNSUPPORTED(GetStringStatus, const fmi2StatusKind s, fmi2String* v)
