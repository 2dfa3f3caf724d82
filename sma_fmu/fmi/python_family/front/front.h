/*
 * front.h - shared declarations of the sma-fmu C front (see fmi2_exports.c).
 *
 * The front is the library a host loads as binaries/linux64/<modelIdentifier>.so or
 * binaries/win64/<modelIdentifier>.dll. It forwards every FMI call to pythonfmu's binary,
 * shipped beside it as <modelIdentifier>_pythonfmu.so / .dll (the "backend"), and fixes what
 * pythonfmu 0.7.0 gets wrong for C hosts: finding and checking a Python, resource URIs,
 * logging, call statuses, fmi2Terminated, serialized states, calls on freed instances,
 * per-thread Python thread states and memory kept after an instance is gone.
 * The operating system is behind platform.h.
 */
#ifndef SMA_FMU_FRONT_H
#define SMA_FMU_FRONT_H

#include "fmi2Functions.h"  /* the standard's header (fmi/c_common/include/): the types, and
                                the prototypes the exports must match */
#include "platform.h"

/* the oldest Python the FMUs run on (their runtime's syntax and library) */
#define PYTHON_MIN_MINOR 10
/* the newest Python 3 minor version looked for when the build's own is absent */
#define PYTHON_MAX_MINOR 40

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

/* ---- the runtime one process shares (backend.c) ------------------------------------------ */
/* One direct step (fast_path.c): the slave's step(t, h, inputs...) with one argument per
 * input settable in stepComplete (slot order): its value if the host set it since the last
 * step, else None. The step returns the values it changed (a tuple: copied to `changed`) or
 * a truth value (it wrote the buffer itself). call_step says: -1 it raised (printed and
 * cleared), 0 not done, 1 done, 2 done and `changed` written, 3 done but the tuple was not
 * n_changed numbers (the values are stale). */
#define STEP_MAX_INPUTS 30
typedef struct {
    double t, h;
    size_t n_inputs;         /* at most STEP_MAX_INPUTS */
    const int* input_slots;  /* their slots */
    const char* input_kinds; /* 'R', 'I' or 'B' */
    const double* values;    /* the buffer's values, by slot */
    const double* pending;   /* the buffer's pending flags, by slot; NULL: none is pending */
    double* changed;         /* out: the values of the slots a step changes (the first ones) */
    size_t n_changed;
} StepCall;

/* What the owner of the backend does for every copy of the front that shares it. */
typedef struct {
    void (*keep_thread_state)(void);
    fmi2Component (*instantiate)(fmi2String name, fmi2Type type, fmi2String guid, fmi2String uri,
                                 const fmi2CallbackFunctions* cb, fmi2Boolean visible);
    void (*forget_resources)(const char* folder);
    /* calls the slave's direct step (GIL taken and released), see StepCall; then
     * *queued = the length of the Python list `queue` (1 if it is none) */
    int (*call_step)(void* callable, void* queue, long* queued, const StepCall* call);
} RuntimeCalls;

/*
 * Hosts unpack an FMU once per instance (fmpy, FmuInstance) and load the front from each
 * folder: each is another copy of the front in memory. The first copy to load pythonfmu's
 * binary owns it (and Python) and stays loaded; it exports this record. A later copy whose
 * backend file has the same build ID takes the owner's backend and runtime calls instead of
 * loading its own, so it holds nothing the host's unloading of it would leave behind.
 */
#define SHARE_MAGIC "SMAFRONT"
#define SHARE_ABI 3 /* 2: RuntimeCalls.call_python; 3: call_step */
typedef struct {
    char magic[8];
    unsigned abi;
    int ready; /* written last, with release order */
    unsigned char backend_id[64];
    size_t backend_id_size;
    Backend backend;
    RuntimeCalls calls;
    char python[1024]; /* which Python, for the log */
    char owner[PATH_SIZE];
} FrontShare;
extern FrontShare sma_fmu_front_share; /* this copy's record (filled if it is an owner) */

/* Loads (or shares) Python and the backend, once per copy of the front; returns 1 on success,
 * else 0 with the reason in load_error. load_info says which Python is used. Their sizes are
 * given here only: write into them with sizeof. */
int load_backend(void);
extern char load_error[2048];
extern char load_info[1024];
void keep_thread_state(void); /* the owner's: one parked Python thread state per host thread */
fmi2Component instantiate_backend(fmi2String name, fmi2Type type, fmi2String guid, fmi2String uri,
                                  const fmi2CallbackFunctions* cb, fmi2Boolean visible);
void forget_resources(const char* folder); /* takes pythonfmu's sys.path entry away again */
int call_step(void* callable, void* queue, long* queued, const StepCall* call); /* -1 without */
int can_call_step(void);                                                         /* 1 if there is one */
/* The GNU build ID of an ELF file (0 elsewhere or without one: then nothing is shared). */
int backend_build_id(const char* path, unsigned char* id, size_t* size);
/* An owner's record for a backend with this build ID, or NULL. */
const FrontShare* find_owner(const unsigned char* id, size_t size);

/* ---- Python (python_runtime.c; finding it: libpython_posix.c, libpython_windows.c) ------- */
/* Makes a Python of a supported version available: the process's own or a loaded one.
 * 0 with the reason in load_error (one line, naming what was tried). */
int load_libpython(void);
void* python_symbol(const char* name);            /* a C-API function of that Python */
int python_library_file(char* path, size_t size); /* its library file (for the init lock) */
/* (python_version.c, below the searches:) 1 if `version` (Py_GetVersion's text) is Python
 * 3.PYTHON_MIN_MINOR or newer; else 0 with the reason in why. */
int python_version_supported(const char* version, char* why, size_t size);
/* Append printf-style text to the string `text` of `size` bytes (truncating, never past it). */
void text_append(char* text, size_t size, const char* format, ...) PRINTF_LIKE(3, 4);
/* The version ("3.11.7") of the Python whose Py_GetVersion is `get_version`, into version
 * (32 bytes); "" when there is none. */
void python_version(void* get_version, char* version);
int start_python_runtime(RuntimeCalls* calls); /* after load_libpython: 1 if the API is there */
extern int use_thread_state_keeper;

/* ---- instances --------------------------------------------------------------------------- */
/* A saved state handed to the host: the front's wrapper around pythonfmu's state, so that a
 * pointer the instance never returned (or already freed) is refused, not dereferenced. */
typedef struct FrontState {
    struct FrontState* next;
    fmi2FMUstate saved; /* pythonfmu's state (a Python object) */
} FrontState;

/* Values the front holds for the slave, so that fmi2Set/Get need no Python (fast_path.c). */
#define FAST_HEADER 12 /* as _HEADER in slave_support/fast_path.py */
#define FAST_DESCRIBE_VR 0xFFFFFA51u /* fmi2GetString: the slave's variable table */
#define FAST_ATTACH_VR 0xFFFFFA52u   /* fmi2SetString: the buffer's address */
#define FAST_SYNC_VR 0xFFFFFA53u     /* fmi2GetString: take pending inputs, write every value */
#define FAST_LOG_VR 0xFFFFFA54u      /* fmi2GetString: pythonfmu passes queued messages on */
typedef struct {
    int attached;            /* the slave writes its values into buffer */
    int stale;               /* a call went to the slave since it last wrote them all */
    int maybe_step_complete; /* the slave may be in stepComplete (else nothing is served) */
    size_t n;                /* slots */
    double* buffer;          /* FAST_HEADER + 2 n doubles: header, values, pending flags */
    unsigned char* settable; /* per slot: settable in stepComplete */
    int* slot_of[3];         /* Real, Integer, Boolean: value reference -> slot or -1 */
    unsigned table_size[3];
    char* kinds;             /* per slot: 'R', 'I' or 'B' */
    int* input_slots;        /* the slots settable in stepComplete, in order */
    char* input_kinds;
    size_t n_inputs;
    size_t n_changed;        /* slots a step changes (the first ones) */
    void* step;              /* the slave's direct doStep (a Python callable), or NULL */
    void* queue;             /* pythonfmu's log queue of the slave (a Python list) */
} FastPath;

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
    /* fmi2LastSuccessfulTime: the front's own after a direct step (pythonfmu's did not run) */
    int own_last_time;
    double last_time;
    int dead; /* the backend returned fmi2Fatal: pythonfmu has freed its objects */
    int freed; /* fmi2FreeInstance was called: only the name is left */
    FrontState* states; /* the states this instance handed out and that are not freed */
    FastPath fast;
} Instance;

/* ---- the fast path (fast_path.c) ------------------------------------------------------------ */
void fast_attach(Instance* in); /* after the slave is created: table and buffer, or nothing */
void fast_free(FastPath* fast);
int fast_ready(Instance* in);   /* 1: serve fmi2Set/Get from the buffer now (may sync first) */
void fast_flush(Instance* in);  /* before a call goes to the slave: hand pending inputs over */
void fast_forwarded(Instance* in, int may_enter_step_complete); /* after it went */
/* 1 if served (every reference known, for fast_set settable now); 0: ask the slave */
int fast_get(Instance* in, char kind, const fmi2ValueReference vr[], size_t nvr, void* value);
int fast_set(Instance* in, char kind, const fmi2ValueReference vr[], size_t nvr, const void* value);
void fast_before_step(Instance* in);
void fast_after_step(Instance* in);
/* fmi2DoStep without pythonfmu: the guard's model-free checks in C, then the slave's step
 * called directly; -1 if not taken (then pythonfmu's DoStep runs, and the guard refuses
 * what C would not take, with its message), else the call's status. */
int fast_step(Instance* in, double t, double h);

/* ---- call status (call_status.c): the lowest layer of the calls ---------------------------- */
fmi2Status refuse(Instance* in, fmi2Status status, const char* function, const char* why);
fmi2Status finish(Instance* in, fmi2Status status); /* the backend's status, or worse if logged */

/* ---- saved states (fmi2_states.c), called by fmi2_exports.c -------------------------------- */
FrontState* find_state(Instance* in, fmi2FMUstate state);
void drop_state(Instance* in, FrontState* state);

/* ---- live instances (instances.c) ----------------------------------------------------------- */
int register_instance(Instance* in); /* 0: out of memory */
/* `c` if it is a live instance of this front; else NULL, after one line on stderr (a freed
 * instance's host callbacks may be gone with it). */
Instance* live_instance(fmi2Component c, const char* function);
/* fmi2FreeInstance: 1 if `c` was live (it is then a freed instance: its memory is kept for
 * a while, so a later call with it is recognized and refused). */
int retire_instance(fmi2Component c);
void free_categories(Instance* in);      /* the logging categories set so far */
void free_instance_memory(Instance* in); /* categories, name, fast-path values, the instance */

/* Every forwarded call starts with this: refuse an unknown or freed instance, and after
 * fmi2Fatal; keep the thread's Python thread state; reset the worst status the slave logged. */
#define ENTER(name)                                                                             \
    Instance* in = live_instance(c, "fmi2" #name);                                              \
    if (!in) return fmi2Error;                                                                  \
    if (in->dead) return refuse(in, fmi2Fatal, "fmi2" #name, "refused: an earlier call returned " \
                                "fmi2Fatal; only fmi2FreeInstance is possible");                \
    keep_thread_state();                                                                        \
    in->logged_status = fmi2OK

/* A call that goes to the slave: pending inputs first (fast_flush), then the call; declares
 * `status`. may_enter: the call can bring the slave into stepComplete. */
#define FORWARD(in, may_enter, call)                                                            \
    fast_flush(in);                                                                             \
    if (in->dead) return refuse(in, fmi2Fatal, __func__, "refused: the slave failed (fmi2Fatal)"); \
    fmi2Status status = finish(in, call);                                                       \
    fast_forwarded(in, may_enter)

/* ---- logging (host_log.c) ---------------------------------------------------------------- */
void host_log(const Instance* in, fmi2Status status, const char* category, const char* message);
void host_logf(const Instance* in, fmi2Status status, const char* format, ...) PRINTF_LIKE(3, 4);
void front_logger(fmi2ComponentEnvironment env, fmi2String instance_name, fmi2Status status,
                  fmi2String category, fmi2String message, ...);
int set_debug_logging(Instance* in, fmi2Boolean on, size_t n, const fmi2String categories[]);
int valid_utf8(const char* text);

/* ---- resource location (resource_uri.c) ------------------------------------------------- */
char* resource_uri_for_pythonfmu(const char* uri, char* err, size_t errlen, char** path_out,
                                 int* plain_path);
int guid_matches(const char* resources, const char* guid, char* err, size_t errlen);

#endif
