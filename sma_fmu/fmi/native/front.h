/*
 * front.h - shared declarations of the sma-fmu native front (see fmi2_exports.c).
 *
 * The front is the library a host loads as binaries/linux64/<modelIdentifier>.so. It
 * forwards every FMI call to pythonfmu's binary, shipped beside it as
 * <modelIdentifier>_pythonfmu.so (the "backend"), and fixes what pythonfmu 0.7.0 gets
 * wrong for C hosts: loading libpython, resource URIs, logging, call statuses,
 * fmi2Terminated, serialized states and per-thread Python thread states.
 */
#ifndef SMA_FMU_FRONT_H
#define SMA_FMU_FRONT_H

#include "fmi2_types.h"

#define EXPORT __attribute__((visibility("default")))

/* ---- the backend: pythonfmu's binary, loaded by backend.c ---------------------------- */
#define BACKEND_FUNCTIONS(X)                                                                     \
    X(fmi2Component, Instantiate, (fmi2String, fmi2Type, fmi2String, fmi2String,                 \
                                   const fmi2CallbackFunctions*, fmi2Boolean, fmi2Boolean))      \
    X(void, FreeInstance, (fmi2Component))                                                       \
    X(fmi2Status, SetupExperiment, (fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean, \
                                    fmi2Real))                                                   \
    X(fmi2Status, EnterInitializationMode, (fmi2Component))                                      \
    X(fmi2Status, ExitInitializationMode, (fmi2Component))                                       \
    X(fmi2Status, Terminate, (fmi2Component))                                                    \
    X(fmi2Status, Reset, (fmi2Component))                                                        \
    X(fmi2Status, GetReal, (fmi2Component, const fmi2ValueReference[], size_t, fmi2Real[]))      \
    X(fmi2Status, GetInteger, (fmi2Component, const fmi2ValueReference[], size_t, fmi2Integer[]))\
    X(fmi2Status, GetBoolean, (fmi2Component, const fmi2ValueReference[], size_t, fmi2Boolean[]))\
    X(fmi2Status, GetString, (fmi2Component, const fmi2ValueReference[], size_t, fmi2String[]))  \
    X(fmi2Status, SetReal, (fmi2Component, const fmi2ValueReference[], size_t, const fmi2Real[]))\
    X(fmi2Status, SetInteger, (fmi2Component, const fmi2ValueReference[], size_t,                \
                               const fmi2Integer[]))                                             \
    X(fmi2Status, SetBoolean, (fmi2Component, const fmi2ValueReference[], size_t,                \
                               const fmi2Boolean[]))                                             \
    X(fmi2Status, SetString, (fmi2Component, const fmi2ValueReference[], size_t,                 \
                              const fmi2String[]))                                               \
    X(fmi2Status, GetFMUstate, (fmi2Component, fmi2FMUstate*))                                   \
    X(fmi2Status, SetFMUstate, (fmi2Component, fmi2FMUstate))                                    \
    X(fmi2Status, FreeFMUstate, (fmi2Component, fmi2FMUstate*))                                  \
    X(fmi2Status, SerializedFMUstateSize, (fmi2Component, fmi2FMUstate, size_t*))               \
    X(fmi2Status, SerializeFMUstate, (fmi2Component, fmi2FMUstate, fmi2Byte[], size_t))         \
    X(fmi2Status, DeSerializeFMUstate, (fmi2Component, const fmi2Byte[], size_t, fmi2FMUstate*))\
    X(fmi2Status, DoStep, (fmi2Component, fmi2Real, fmi2Real, fmi2Boolean))                      \
    X(fmi2Status, GetRealStatus, (fmi2Component, const fmi2StatusKind, fmi2Real*))

#define DECLARE_POINTER(ret, name, args) ret(*name) args;
typedef struct {
    BACKEND_FUNCTIONS(DECLARE_POINTER)
} Backend;
#undef DECLARE_POINTER

extern Backend backend;

/* Loads libpython (if the process has none) and the backend once per process; returns 1 on
 * success, else 0 with the reason in load_error. load_info says which libpython is used.
 * Their sizes are given here only: write into them with sizeof. */
int load_backend(void);
extern char load_error[2048];
extern char load_info[1024];

/* ---- the embedded Python (python_runtime.c) --------------------------------------------- */
int ensure_libpython(void);          /* 1: the Python C API is in the global scope */
int resolve_python_api(void);        /* 1: the functions below were found */
void keep_thread_state(void);        /* one parked Python thread state per host thread */
int python_is_initialized(void);
fmi2Component instantiate_backend_locked(fmi2String name, fmi2Type type, fmi2String guid,
                                         fmi2String uri, const fmi2CallbackFunctions* cb,
                                         fmi2Boolean visible);
extern int use_thread_state_keeper;

/* ---- instances --------------------------------------------------------------------------- */
/* A saved state handed to the host: the front's wrapper around pythonfmu's state, so that a
 * pointer the instance never returned (or already freed) is refused, not dereferenced. */
typedef struct FrontState {
    struct FrontState* next;
    fmi2FMUstate saved; /* pythonfmu's state (a Python object) */
} FrontState;

typedef struct {
    fmi2Component backend;
    fmi2CallbackFunctions callbacks; /* what pythonfmu gets; it keeps the pointer */
    fmi2CallbackLogger host_logger;
    fmi2ComponentEnvironment host_environment;
    char* name;
    /* the host's logging settings (fmi2Instantiate's loggingOn, fmi2SetDebugLogging) */
    int log_all;          /* every category on */
    int log_problems;     /* warnings, discards and errors: on unless switched off */
    char** categories;
    size_t n_categories;
    /* the worst status the slave logged during the call being forwarded */
    fmi2Status logged_status;
    /* fmi2Terminated and fmi2GetXXXStatus bookkeeping */
    int stepped, terminated, have_discard;
    double discard_time, discard_step;
    int dead; /* the backend returned fmi2Fatal: pythonfmu has freed its objects */
    FrontState* states; /* the states this instance handed out and that are not freed */
} Instance;

/* ---- forwarding (fmi2_exports.c) and saved states (fmi2_states.c) ----------------------- */
fmi2Status refuse(Instance* in, fmi2Status status, const char* function, const char* why);
fmi2Status finish(Instance* in, fmi2Status status); /* the backend's status, or worse if logged */
FrontState* find_state(Instance* in, fmi2FMUstate state);
void drop_state(Instance* in, FrontState* state);

/* Every forwarded call starts with this: refuse after fmi2Fatal, keep the thread's Python
 * thread state, and reset the worst status the slave logged. */
#define ENTER(name)                                                                             \
    Instance* in = (Instance*)c;                                                                \
    if (!in) return fmi2Error;                                                                  \
    if (in->dead) return refuse(in, fmi2Fatal, "fmi2" #name, "refused: an earlier call returned " \
                                "fmi2Fatal; only fmi2FreeInstance is possible");                \
    keep_thread_state();                                                                        \
    in->logged_status = fmi2OK

/* ---- logging (host_log.c) ---------------------------------------------------------------- */
void host_log(const Instance* in, fmi2Status status, const char* category, const char* message);
void host_logf(const Instance* in, fmi2Status status, const char* format, ...)
    __attribute__((format(printf, 3, 4)));
void front_logger(fmi2ComponentEnvironment env, fmi2String instance_name, fmi2Status status,
                  fmi2String category, fmi2String message, ...);
int set_debug_logging(Instance* in, fmi2Boolean on, size_t n, const fmi2String categories[]);
int valid_utf8(const char* text);

/* ---- resource location (resource_uri.c) ------------------------------------------------- */
char* resource_uri_for_pythonfmu(const char* uri, char* err, size_t errlen, char** path_out,
                                 int* plain_path);
int guid_matches(const char* resources, const char* guid, char* err, size_t errlen);

/* ---- serialized states (state_bytes.c) --------------------------------------------------- */
#define STATE_HEADER_SIZE 20
void write_state_header(fmi2Byte* bytes, size_t payload_size);
int state_header_valid(const fmi2Byte* bytes, size_t size);

#endif
