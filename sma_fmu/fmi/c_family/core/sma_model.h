/* The contract between the core (core/, under the fronts fmi2/ and fmi3/) and a model
 * adapter (fmi/models/<Model>/<Model>.c).
 *
 * Like the Reference-FMUs' model.h, nothing here is FMI: an adapter declares its variables
 * (a generated table, <Model>_variables.h) and a few functions over its runtime stepper;
 * the core owns the values, the calling sequence, the checks, the log and the saved
 * states, and the fronts translate them to an FMI version. The adapters are as thin as the
 * pythonfmu slaves beside them (fmi/models/<Model>/) and keep their semantics: a failing start
 * refuses ExitInitializationMode, a failing step discards it (slave_support/guards.py). */
#ifndef SMA_MODEL_H
#define SMA_MODEL_H

#include <stddef.h>

#include "sma_message.h"

typedef enum { SMA_REAL, SMA_INTEGER, SMA_BOOLEAN, SMA_STRING } SmaKind;
typedef enum { SMA_PARAMETER, SMA_INPUT, SMA_OUTPUT } SmaCausality;
typedef enum { SMA_FIXED, SMA_TUNABLE, SMA_DISCRETE, SMA_CONTINUOUS } SmaVariability;

/* One variable, as the pythonfmu FMU declares it (generated from its model description). */
typedef struct {
    unsigned int vr;            /* value reference */
    const char *name;
    SmaKind kind;
    SmaCausality causality;
    SmaVariability variability;
    double start;               /* Real, Integer, Boolean (0/1) start value */
    const char *start_text;     /* String start value (NULL for the others) */
    int wire;                   /* index in PARAMETER_SPECS of a wire parameter, else -1 */
    const char *unit;           /* its unit, e.g. "ohm" (NULL: none) */
} SmaVariable;

/* A variable's present value: Real -> real, Integer and Boolean -> integer, String -> text
 * (owned by the layer). */
typedef union {
    double real;
    int integer;
    char *text;
} SmaValue;

/* What the layer knows about the run that a model may use (slave_support/interface.py). */
typedef struct {
    const char *model_name;
    const char *instance_name;
    double start_time;          /* fmi2SetupExperiment's startTime [s] (0 until set) */
    double first_step;          /* h0 [s], the first step's size; <= 0 until the first step */
    const double *wire_defaults;  /* the build's wire parameter file (resources/model_starts.json), */
    size_t wire_count;            /* in PARAMETER_SPECS order, NaN where not given */
} SmaRun;

/* A step within GRID_TOLERANCE steps of h0 is taken as h0 (SlaveInterface.nominal_step):
 * returns h0 (setting it from `step_size` [s] at the first step) or `step_size`. */
double sma_nominal_step(SmaRun *run, double step_size);

/* A model: its variables and its stepper behind five functions. Each `int` function returns
 * 0 or, with `message` filled (the runtime's ValueError text), nonzero; on error it changes
 * neither the stepper nor the values. */
typedef struct {
    const char *name;                 /* modelName and modelIdentifier */
    const char *guid;
    const char *state_format;         /* names the stepper's saved-state layout (its header) */
    const char *log_categories[8];    /* those of the model description, NULL-terminated */
    const SmaVariable *variables;
    size_t count;
    int snaps_step;                   /* 1: the layer applies sma_nominal_step (StepperSlave) */
    size_t stepper_size;              /* bytes of the stepper the layer allocates (zeroed) */
    /* A new stepper in `stepper` from the parameters and inputs in `values`; writes the
     * outputs after initialization into `values` (StepperSlave._start + _publish). */
    int (*start)(void *stepper, SmaValue *values, SmaRun *run, SmaMessage *message);
    /* One step from t = `time` [s] by `step` [s] (already nominal if snaps_step). */
    int (*step)(void *stepper, SmaValue *values, SmaRun *run, double time, double step,
                SmaMessage *message);
    void (*free)(void *stepper);      /* heap memory of a started stepper (may be NULL) */
    const char *(*warning)(const void *stepper); /* validity warning of the last step, or "" */
    size_t (*state_size)(const void *stepper);
    void (*state_write)(const void *stepper, double *out);
    int (*state_read)(void *stepper, const double *in, size_t count, SmaMessage *message);
    /* FMI 3.0 event mode: the time [s] of the model's next discontinuity after `time` [s]
     * with the present inputs; NULL: the model has no events of its own. */
    double (*next_event)(const void *stepper, const SmaValue *values, double time);
    /* FMI 3.0 arrays (FMI 2.0 declares none): `array_count` Float64 array outputs, each as
     * long as the value of the Integer parameter at `array_size` (in FMI 3.0 a structural
     * parameter). get_array, the Reference-FMUs' accessor: array number `array` of the
     * started stepper into values[*index ..], advancing *index by its length (live entries
     * first, the rest NaN: docs/fmus.md, "Arrays"); nonzero, nothing written, if fewer than that many
     * of nValues are left. live_count: its entries in use. NULL, 0: no arrays. */
    size_t array_count;
    size_t array_size;
    int (*get_array)(const void *stepper, const SmaValue *values, size_t array, double values_out[],
                     size_t nValues, size_t *index);
    size_t (*live_count)(const void *stepper);
    /* The outputs of a started stepper into `values`, every output (the adapter's publish):
     * a restored state's saved outputs must be these (layer_states.c). NULL: the outputs are
     * not held by the stepper (the model computes them from its inputs in a step), and a
     * state's outputs are checked to be finite only. */
    void (*held_outputs)(const void *stepper, SmaValue *values);
} SmaModel;


/* Each adapter defines this one object (fmi/models/<Model>/<Model>.c). */
extern const SmaModel SMA_MODEL;

#endif
