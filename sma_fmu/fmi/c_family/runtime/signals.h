/* Scenario signals: the reference R_ref(t) [ohm] and the piecewise-constant load f(t) [kg];
 * runtime/signals.py.
 *
 * Built from a scenario's [reference] and [load] tables, here parsed JSON objects
 * (json_text.h). Problems are refused with Python's ValueError text naming the key (values
 * shown as Python's repr). A signal owns heap memory (its table): free it with
 * reference_signal_free / load_profile_free. */
#ifndef SMA_SIGNALS_H
#define SMA_SIGNALS_H

#include <stddef.h>

#include "json_text.h"
#include "sma_message.h"

#define MAX_REFERENCE_OHM 1e6   /* a wire's resistance is ohms to kilo-ohms; beyond is a typo */
#define LOAD_TOLERANCE_S 1e-9   /* LoadProfile.value's default tolerance [s] */

/* REFERENCE_KINDS: a kind is its index in ("constant", "step", "ramp", "sine", "cosine",
 * "table"). */
typedef enum ReferenceKind {
    REFERENCE_CONSTANT, REFERENCE_STEP, REFERENCE_RAMP, REFERENCE_SINE, REFERENCE_COSINE,
    REFERENCE_TABLE, REFERENCE_KIND_COUNT
} ReferenceKind;
extern const char *const REFERENCE_KINDS[REFERENCE_KIND_COUNT];

/* R_ref(t) [ohm]: one of the kinds with its settings (the fields of that kind are used). */
typedef struct ReferenceSignal {
    ReferenceKind kind;
    double value_ohm;                           /* constant */
    double initial_ohm, final_ohm, time_s;      /* step */
    double start_ohm, end_ohm, start_time_s, end_time_s;            /* ramp */
    double offset_ohm, amplitude_ohm, frequency_hz, phase_deg;       /* sine, cosine */
    size_t count;                               /* table: points in ... */
    double *times_s;                            /* ... times_s [s] (strictly increasing) */
    double *values_ohm;                         /* ... and values_ohm [ohm] (heap) */
} ReferenceSignal;

/* Piecewise-constant load: values_kg[i] from times_s[i] on (the first time is 0 s). */
typedef struct LoadProfile {
    size_t count;
    double *times;    /* [s] (heap) */
    double *values;   /* [kg] (heap) */
} LoadProfile;

/* ReferenceSignal(kind, settings)'s check of a filled signal: its bounds must lie in
 * (0, MAX_REFERENCE_OHM] ("the reference must stay > 0 ohm, but reaches ..."). */
int reference_signal_check(const ReferenceSignal *signal, SmaMessage *message);
/* (lowest, highest) value of R_ref over all time [ohm]. */
void reference_signal_bounds(const ReferenceSignal *signal, double *lowest, double *highest);
/* R_ref [ohm] at time t [s]. Refused as Python's math.sin/cos refuse an infinite angle
 * ("math domain error"); a NaN result is passed on as in Python. */
int reference_signal_value(const ReferenceSignal *signal, double t, double *value,
                           SmaMessage *message);
/* +1 or -1: the sign of the change the reference last made at or before t [s] (its slope
 * where it moves; +1 while it never moved); ReferenceSignal.trend. */
int reference_signal_trend(const ReferenceSignal *signal, double t);
void reference_signal_free(ReferenceSignal *signal);

/* Load [kg] at t [s]; a switching time within `tolerance` [s] counts as reached (before
 * the first time: the last value, as Python's index -1). */
double load_profile_value(const LoadProfile *load, double t, double tolerance);
void load_profile_free(LoadProfile *load);

/* A ReferenceSignal / LoadProfile from a scenario's [reference] / [load] table (a
 * JSON_OBJECT); refused with Python's message naming the key. *out is filled only on
 * success (then owned by the caller). */
int reference_from_table(const JsonValue *table, ReferenceSignal *out, SmaMessage *message);
int load_from_table(const JsonValue *table, LoadProfile *out, SmaMessage *message);

#endif
