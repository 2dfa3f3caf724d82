/* The FMI 2.0 co-simulation layer shared by the five native models (private header).
 *
 * One Instance per fmi2Instantiate. Its calling-sequence states, refusals and messages are
 * those of the pythonfmu FMUs' guard (slave_support/guards.py, lifecycle.py, interface.py),
 * so both families refuse the same calls with the same status, and their messages name the
 * same function and variable. Every message goes to the host's logger as a "%s" argument,
 * never as a format. */
#ifndef SMA_FMI2_LAYER_H
#define SMA_FMI2_LAYER_H

#include <stddef.h>
#include <stdint.h>

#include "fmi2Functions.h"
#include "sma_model.h"

/* lifecycle.py's states, in STATES order; the texts are the states' names there */
typedef enum {
    STATE_INSTANTIATED,
    STATE_INITIALIZATION,
    STATE_STEP_COMPLETE,
    STATE_TERMINATED,
    STATE_ERROR,
    STATE_COUNT
} LayerState;
extern const char *const STATE_NAMES[STATE_COUNT];

/* A saved state handed to the host (fmi2GetFMUstate): the serialized bytes, so that a set,
 * a serialization and a deserialization all take the same checked path. */
typedef struct SavedState {
    struct SavedState *next;
    size_t size;
    unsigned char *bytes;
} SavedState;

typedef struct Instance {
    struct Instance *chain;          /* next instance of its registry chain (fmi2_instances.c) */
    int freed;                       /* freed by fmi2FreeInstance, kept (read under the lock) */
    const SmaModel *model;
    char *name;
    char *guid;
    char *resources;                 /* the resources folder (a path), or NULL */
    fmi2CallbackLogger logger;
    fmi2ComponentEnvironment environment;
    int log_all, log_problems;       /* host_log.c's rules, see fmi2_log.c */
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
    fmi2Status worst;                /* worst status logged during the present call */
    int stepped, terminated, have_discard;  /* fmi2GetXXXStatus bookkeeping (as the front) */
    double discard_time, discard_step;
    SavedState *states;              /* states handed out and not freed */
    double *wire_defaults;           /* run.wire_defaults (malloc'd; fmi2_start_values.c) */
} Instance;

/* ---- calls (fmi2_functions.c) -------------------------------------------------------------- */
/* `c` if it is a live instance (fmi2_instances.c), its worst status reset; else NULL, with
 * one line on stderr naming `function`. */
Instance *layer_instance(fmi2Component c, const char *function);
#define ENTER                                                                                 \
    Instance *in = layer_instance(c, __func__);                                               \
    if (!in) return fmi2Error
#define IN(state) (1u << (state))
/* The call's status: `status`, or worse if the call logged worse. */
fmi2Status layer_finish(const Instance *in, fmi2Status status);
/* guard.allowed: 1 if the present state is one of the IN(...) bits of `mask`, else refused. */
int layer_allowed(Instance *in, const char *function, unsigned int mask);
/* guard.validity: the stepper's validity warning of its last start or step, as fmi2Warning. */
void layer_validity(Instance *in, const char *function);

/* ---- instances (fmi2_instances.c) -------------------------------------------------------- */
/* Every call looks its pointer up here before reading through it (thread-safe). */
void layer_register(Instance *in);           /* a new instance: live from now on */
/* The live instance at `pointer`, or NULL with one stderr line naming `function` (and the
 * instance, if it was freed); nothing is read through `pointer` unless it is registered. */
Instance *layer_live(const void *pointer, const char *function);
/* The same, and the instance returned is marked freed: every later lookup refuses it. The
 * caller releases what it holds (not its name), then hands it to layer_keep. */
Instance *layer_retire(const void *pointer, const char *function);
/* Keeps a retired instance allocated among the last ones freed; releases the oldest. */
void layer_keep(Instance *in);

/* ---- log (fmi2_log.c) -------------------------------------------------------------------- */
/* "<model> '<instance>': <text>" to the host's logger with `status` (which the call then
 * returns at least); the text is formatted here from our literal `format`. */
void layer_log(Instance *in, fmi2Status status, const char *format, ...)
#if defined(__GNUC__) && defined(__MINGW32__)
    __attribute__((format(gnu_printf, 3, 4)))
#elif defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* A refused call: logs "<function>: <why>" with `status`, returns it. */
fmi2Status layer_refuse(Instance *in, fmi2Status status, const char *function, const char *why);
/* The same without the "<model> '<instance>': " prefix: the refusals the pythonfmu FMUs'
 * front makes before a call reaches the slave (argument checks, unsupported functions,
 * saved-state pointers), worded as there. */
void layer_plain(Instance *in, fmi2Status status, const char *format, ...)
#if defined(__GNUC__) && defined(__MINGW32__)
    __attribute__((format(gnu_printf, 3, 4)))
#elif defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
fmi2Status layer_reject(Instance *in, fmi2Status status, const char *function, const char *why);
int layer_set_debug_logging(Instance *in, int on, size_t n, const fmi2String categories[]);
int layer_valid_utf8(const char *text);
/* Python's repr of a float ("1.0", "1e-05", "nan", "inf") into `text` (32 bytes). */
void layer_repr(double value, char *text);

/* ---- variables (fmi2_variables.c) -------------------------------------------------------- */
int layer_values_init(Instance *in);          /* start values; 0: out of memory */
void layer_values_free(const SmaModel *model, SmaValue *values);
SmaValue *layer_values_copy(const SmaModel *model, const SmaValue *values); /* NULL: no memory */
const SmaVariable *layer_variable(const SmaModel *model, unsigned int vr, size_t *index);
fmi2Status layer_get(Instance *in, const char *function, SmaKind kind,
                     const fmi2ValueReference vr[], size_t nvr, void *value);
fmi2Status layer_set(Instance *in, const char *function, SmaKind kind,
                     const fmi2ValueReference vr[], size_t nvr, const void *value);
int layer_outputs_finite(const Instance *in, const SmaValue *values);
/* Initialization Mode: the outputs from what was set (guard._refresh_initial_outputs). */
int layer_refresh_outputs(Instance *in, const char *function);
/* The model's start on the present values (guard._run_initialization): 0 or the reason in
 * `why`. */
int layer_run_initialization(Instance *in, char *why, size_t size);
void layer_drop_stepper(Instance *in);

/* ---- saved states (fmi2_states.c, fmi2_state_bytes.c) ------------------------------------ */
void layer_free_states(Instance *in);
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

/* ---- resources (fmi2_resources.c) -------------------------------------------------------- */
/* The folder of a file: URI (or a plain absolute path) in `folder` (malloc'd), or 0 with the
 * reason in `why`; *plain = 1 for a plain path. */
int layer_resource_folder(const char *uri, char **folder, int *plain, char *why, size_t size);
/* The checked text of the start-values file at `path` (fmi2_start_file.c; malloc'd), or NULL
 * with the reason in `why`, or NULL with *missing = 1 when there is no such file. */
char *layer_start_file(const char *path, int *missing, char *why, size_t size);
/* Packed start values (resources/start_values.json), if the FMU has them. */
int layer_packed_start_values(Instance *in, char *why, size_t size);
/* The build's start values of every variable and its wire parameter file
 * (resources/model_starts.json, which every C-family FMU holds). */
int layer_build_starts(Instance *in, char *why, size_t size);

#endif
