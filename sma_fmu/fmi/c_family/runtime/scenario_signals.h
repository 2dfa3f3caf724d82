/* A scenario's signals as a co-simulation source, read from the text of FMI String
 * parameters; runtime/scenario_signals.py.
 *
 * The SmaScenarioSignals FMU takes a scenario's [reference] and [load] tables as two String
 * parameters, `reference` and `load_profile`, each holding its table as a JSON object
 * (json_text.h), checked as check scenario files do (signals.h) with the same messages.
 *
 * choice (the time grid, see the Python module): SignalSource samples at start + k h, h the
 * size of its first step, whenever the end of a step lies within GRID_TOLERANCE steps of
 * that point; elsewhere at the host's time.
 *
 * Saved state (signal_source_state_*): 1 double, [0] time of the outputs [s] (>= 0). */
#ifndef SMA_SCENARIO_SIGNALS_H
#define SMA_SCENARIO_SIGNALS_H

#include <stddef.h>

#include "signals.h"
#include "sma_message.h"

#define GRID_TOLERANCE 1e-6   /* [steps]: a time this close to start + k h is that point */

/* Reference resistance R_ref [ohm] and load [kg] at one time. */
typedef struct SignalOutputs {
    double R_ref;
    double load;
} SignalOutputs;

/* (ReferenceSignal, LoadProfile) from the two JSON texts (UTF-8, NUL-terminated; NULL reads
 * as Python's None); refused with Python's message, which names the parameter ("reference"
 * or "load_profile") and the key. On success the caller owns *reference and *load. */
int signals_from_text(const char *reference_text, const char *load_text,
                      ReferenceSignal *reference, LoadProfile *load, SmaMessage *message);

/* grid_point: 1 and *grid = start_s + k step_s [s] for the k nearest time_s [s] when time_s
 * lies within GRID_TOLERANCE steps of it; 0 (Python's None) otherwise. Not an error code. */
int grid_point(double time_s, double start_s, double step_s, double *grid);
/* grid_point of time_s [s], or time_s itself when it is off the grid. */
double grid_time(double time_s, double start_s, double step_s);

/* R_ref(t) and the load f(t) at the communication points of a co-simulation. */
typedef struct SignalSource {
    ReferenceSignal reference;   /* owned: freed by signal_source_free */
    LoadProfile load;            /* owned */
    double start_time;           /* [s] */
    double time;                 /* [s]: the time of the outputs */
    int has_grid_step;           /* 0: Python's grid_step None (no step yet) */
    double grid_step;            /* h_0 [s], the first step's size */
    SignalOutputs outputs;       /* at `time` */
} SignalSource;

/* Takes ownership of *reference and *load (also when it refuses: they are then freed).
 * start_time must be finite ("start time"); the outputs are those at start_time. */
int signal_source_init(SignalSource *source, ReferenceSignal *reference, LoadProfile *load,
                       double start_time, SmaMessage *message);
/* Advance from current_time [s] by step_size [s]; *outputs (also source->outputs) at the
 * end. Refused naming "current time", "step_size" or "current time + step_size"; a
 * refusal after the first step's size was taken keeps it, as in Python. */
int signal_source_step(SignalSource *source, double current_time, double step_size,
                       SignalOutputs *outputs, SmaMessage *message);
void signal_source_free(SignalSource *source);

size_t signal_source_state_size(const SignalSource *source);
void signal_source_state_write(const SignalSource *source, double *out);
/* "state entry time = ... must be finite and in [0, inf] s"; nothing changes on a refusal. */
int signal_source_state_read(SignalSource *source, const double *in, size_t count,
                             SmaMessage *message);

#endif
