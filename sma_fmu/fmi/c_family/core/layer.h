/* The version-neutral core under both FMI fronts (fmi2/, fmi3/) of the native models.
 *
 * As in the Reference-FMUs, the core owns what does not depend on the FMI version: the
 * instance, its calling-sequence state, the variables and their checks, the start values,
 * the saved states, the log's filtering and wording. A front only translates its version's
 * types and calls; it passes its own function names, so every message names the function
 * the host called ("fmi2DoStep", "fmi3DoStep"). The states, refusals and messages are those
 * of the pythonfmu FMUs' guard (slave_support/guards.py, lifecycle.py, interface.py), so
 * both families refuse the same calls with the same status. Every message goes to the
 * host's logger as text (FMI 2.0: a "%s" argument), never as a format. */
#ifndef SMA_LAYER_H
#define SMA_LAYER_H

#include <stddef.h>
#include <stdint.h>

#include "sma_model.h"

/* The statuses, with FMI 2.0's and FMI 3.0's numbering (both order them alike). */
typedef enum { SMA_OK, SMA_WARNING, SMA_DISCARD, SMA_ERROR, SMA_FATAL } SmaStatus;

/* lifecycle.py's states, in STATES order; the texts are the states' names there. */
typedef enum {
    STATE_INSTANTIATED,
    STATE_INITIALIZATION,
    STATE_STEP_COMPLETE,
    STATE_TERMINATED,
    STATE_ERROR,
    STATE_COUNT
} LayerState;
extern const char *const STATE_NAMES[STATE_COUNT];

/* A saved state handed to the host (Get FMU state): the serialized bytes, so that a set,
 * a serialization and a deserialization all take the same checked path. */
typedef struct SavedState {
    struct SavedState *next;
    size_t size;
    unsigned char *bytes;
} SavedState;

struct Instance;
/* How a front hands one message to its host's logger (the text is never a format). */
typedef void (*LayerEmit)(const struct Instance *in, SmaStatus status, const char *category,
                          const char *text);

typedef struct Instance {
    struct Instance *chain;          /* next instance of its registry chain (layer_instances.c) */
    int freed;                       /* freed by FreeInstance, kept (read under the lock) */
    const SmaModel *model;
    const char *prefix;              /* "fmi2" or "fmi3": the front's function names */
    char *name;
    char *guid;                      /* the GUID (FMI 2.0) or instantiation token (FMI 3.0) */
    char *resources;                 /* the resources folder (a path), or NULL */
    LayerEmit emit;                  /* the front's logger call */
    void (*logger)(void);            /* the host's logger, as the front's type casts it back */
    void *environment;               /* the host's component/instance environment */
    int log_all, log_problems;       /* host_log.c's rules, see layer_log.c */
    char *categories;                /* enabled categories, each followed by '\n' */
    LayerState state;
    SmaRun run;
    double stop_time;
    int stop_defined;
    int time_defined;
    double time;                     /* the next communication point [s] */
    int outputs_current;             /* Initialization Mode: outputs reflect what was set */
    char initial_error[512];         /* why the outputs cannot be computed, or "" */
    SmaValue *values;                /* one per variable of the model */
    size_t *real_outputs;            /* the indices of the Real outputs, found once */
    size_t real_output_count;        /* (layer_outputs_finite checks only those) */
    void *stepper;                   /* started stepper, or NULL */
    SmaStatus worst;                 /* worst status logged during the present call */
    int stepped, terminated, have_discard;  /* GetXXXStatus bookkeeping (as the front) */
    double discard_time, discard_step;
    SavedState *states;              /* states handed out and not freed */
    double *wire_defaults;           /* run.wire_defaults (malloc'd; layer_start_values.c) */
    /* the build's identity, from resources/model_starts.json (layer_start_values.c): the
     * wire's digest ("sha256:" + 64 hex digits) and the GUID/instantiation token of the
     * model description it belongs to, which the host must pass */
    char wire_digest[80];
    char build_token[80];
    /* FMI 3.0 only (its front sets and reads them; not in saved states): */
    int event_mode_used, early_return;  /* fmi3InstantiateCoSimulation's flags */
    int event_mode;                  /* in Event Mode (the core's state is then stepComplete) */
    int configuration_mode;          /* in Configuration Mode (the core's state: instantiated) */
} Instance;

/* ---- calls (layer_calls.c) --------------------------------------------------------------- */
/* `c` if it is a live instance (layer_instances.c), its worst status reset; else NULL, with
 * one line on stderr naming `function`. */
Instance *layer_instance(const void *c, const char *function);
#define IN(state) (1u << (state))
/* The call's status: `status`, or worse if the call logged worse. */
SmaStatus layer_finish(const Instance *in, SmaStatus status);
/* guard.allowed: 1 if the present state is one of the IN(...) bits of `mask`, else refused. */
int layer_allowed(Instance *in, const char *function, unsigned int mask);
/* guard.validity: the stepper's validity warning of its last start or step, as a warning. */
void layer_validity(Instance *in, const char *function);
/* A new instance of SMA_MODEL for the front `prefix` (not yet registered), its name checked
 * and copied, or NULL (out of memory, or a refused name: logged through `emit`). */
Instance *layer_new(const char *prefix, const char *instance_name, LayerEmit emit,
                    void (*logger)(void), void *environment, int logging_on);
/* The checks of Instantiate after the name: the token/GUID, the resource location, the
 * start values; 1: registered and live; 0: refused (logged), `in` freed. */
int layer_instantiate(Instance *in, const char *function, const char *token,
                      const char *token_name, const char *resource_location);
void layer_free(Instance *in, const char *function);    /* FreeInstance */
void layer_discard(Instance *in);   /* an instance a front refuses before it is registered */
/* Back to the state of a new instance (Instantiate, Reset); 0 with `why`. */
int layer_initial_state(Instance *in, char *why, size_t size);
SmaStatus layer_setup(Instance *in, const char *function, double start_time, int stop_defined,
                      double stop_time);
SmaStatus layer_enter_initialization(Instance *in, const char *function);
SmaStatus layer_exit_initialization(Instance *in, const char *function, LayerState next);
/* The front's argument checks of an array call; 0: refused (status in *status). */
int layer_arrays_ok(Instance *in, const char *function, const void *vr, size_t nvr,
                    const void *value, SmaStatus *status);

/* ---- instances (layer_instances.c) ------------------------------------------------------- */
void layer_register(Instance *in);           /* a new instance: live from now on */
Instance *layer_live(const void *pointer, const char *function);
Instance *layer_retire(const void *pointer, const char *function);
void layer_keep(Instance *in);

/* ---- step (layer_step.c) ----------------------------------------------------------------- */
/* guard._do_step with the discard bookkeeping: the step from t by h, or its refusal. */
SmaStatus layer_step(Instance *in, const char *function, double t, double h);

/* ---- log (layer_log.c) ------------------------------------------------------------------- */
/* "<model> '<instance>': <text>" to the host's logger with `status` (which the call then
 * returns at least); the text is formatted here from our literal `format`. */
void layer_log(Instance *in, SmaStatus status, const char *format, ...)
#if defined(__GNUC__) && defined(__MINGW32__)
    __attribute__((format(gnu_printf, 3, 4)))
#elif defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* A refused call: logs "<function>: <why>" with `status`, returns it. */
SmaStatus layer_refuse(Instance *in, SmaStatus status, const char *function, const char *why);
/* The same without the "<model> '<instance>': " prefix: the refusals the pythonfmu FMUs'
 * front makes before a call reaches the slave (argument checks, unsupported functions,
 * saved-state pointers), worded as there. */
void layer_plain(Instance *in, SmaStatus status, const char *format, ...)
#if defined(__GNUC__) && defined(__MINGW32__)
    __attribute__((format(gnu_printf, 3, 4)))
#elif defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
SmaStatus layer_reject(Instance *in, SmaStatus status, const char *function, const char *why);
int layer_set_debug_logging(Instance *in, int on, size_t n, const char *const categories[]);
int layer_valid_utf8(const char *text);
/* Python's repr of a float ("1.0", "1e-05", "nan", "inf") into `text` (32 bytes). */
void layer_repr(double value, char *text);

/* ---- variables (layer_variables.c) ------------------------------------------------------- */
/* Values cross the core as double (Real), int (Integer, Boolean 0/1) and const char *. */
int layer_values_init(Instance *in);          /* start values; 0: out of memory */
void layer_values_free(const SmaModel *model, SmaValue *values);
SmaValue *layer_values_copy(const SmaModel *model, const SmaValue *values); /* NULL: no memory */
const SmaVariable *layer_variable(const SmaModel *model, unsigned int vr, size_t *index);
SmaStatus layer_get(Instance *in, const char *function, SmaKind kind, const unsigned int vr[],
                    size_t nvr, void *value);
SmaStatus layer_set(Instance *in, const char *function, SmaKind kind, const unsigned int vr[],
                    size_t nvr, const void *value);
int layer_outputs_finite(const Instance *in, const SmaValue *values);
/* Initialization Mode: the outputs from what was set (guard._refresh_initial_outputs). */
int layer_refresh_outputs(Instance *in, const char *function);
/* The model's start on the present values (guard._run_initialization): 0 or the reason in
 * `why`. */
int layer_run_initialization(Instance *in, char *why, size_t size);
void layer_drop_stepper(Instance *in);

/* ---- saved states (layer_states.c, layer_state_bytes.c) ---------------------------------- */
void layer_free_states(Instance *in);
SavedState *layer_find_state(Instance *in, const void *state);
/* Get: the state of `in` into *state (NULL: a new one, else one of this instance's). */
SmaStatus layer_get_state(Instance *in, const char *function, void **state);
SmaStatus layer_set_state(Instance *in, const char *function, const void *state);
SmaStatus layer_free_state(Instance *in, const char *function, void **state);
SmaStatus layer_serialize_state(Instance *in, const char *function, const void *state,
                                unsigned char bytes[], size_t size);
SmaStatus layer_deserialize_state(Instance *in, const char *function, const unsigned char bytes[],
                                  size_t size, void **state);
/* A state read from bytes, checked but not applied. */
typedef struct {
    uint32_t state;
    double start_time, stop_time, time, first_step;
    int stop_defined, time_defined, outputs_current, has_stepper;
    char *initial_error;
    SmaValue *values;
    double *doubles;
    uint32_t count;
} Parsed;
/* The serialized state of `in` (malloc'd, framed) and its size; NULL: out of memory. */
unsigned char *layer_serialize(const Instance *in, size_t *size);
/* 1 with *p filled (free it with layer_parsed_free), or 0 with the reason in `why`.
 * `framed`: the frame was checked already (bytes the instance wrote or deserialized). */
int layer_parse_state(const Instance *in, const unsigned char *bytes, size_t size, int framed,
                      Parsed *p, char *why, size_t why_size);
void layer_parsed_free(const SmaModel *model, Parsed *p);

/* ---- resources (layer_resources.c, layer_start_file.c, layer_start_values.c) ------------- */
int layer_resource_folder(const char *uri, char **folder, int *plain, char *why, size_t size);
char *layer_start_file(const char *path, int *missing, char *why, size_t size);
int layer_packed_start_values(Instance *in, char *why, size_t size);
/* The build's start values of every variable and its wire parameter file
 * (resources/model_starts.json, which every C-family FMU holds), and its identity: the
 * structure it was built for must be this binary's (model->guid). */
int layer_build_starts(Instance *in, char *why, size_t size);

#endif
