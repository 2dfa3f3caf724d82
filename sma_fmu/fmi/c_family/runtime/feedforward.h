/* Stateful feedforward compensator: temperature-sensing inverse + phase-lag filter (spec
 * section 10); runtime/feedforward.py.
 *
 *     R_ref, f -> T_ref = inverse(R_ref, f, d_ref) -> v = (T_ref - T_room)/K_th -> u_ff = Cpl(s) v
 *
 * d_ref comes from successive reference samples: a falling R_ref means heating (+1), a rising
 * one cooling (-1), an equal one keeps the last; the first sample is heating. With
 * adapt_to_load the measured load enters the inverse, otherwise model_load.
 *
 * Two inverses (INVERSES, by index): "major" (the paper's: the major branch of d_ref) and
 * "minor-loop" (the branch the plant's continuous mode is on: the compensator keeps its own
 * stack of reversal points with the plant's rules, pushing (T_ref,k-1, xi_MF,k-1) when d_ref
 * changes, inverted by invert_on_stack). In both, a reference outside what the branch reaches
 * at the present load gives the temperature of the nearest reachable edge, saturated = 1.
 *
 * Two shapings (SHAPINGS, shaping.h): "none" (the paper's phase-lag filter) and "reachable"
 * (the demand shaped into what a model of the wire can reach in a step, up to power_cap; the
 * inverse then takes the model's memory; P_ff is the model's power, no filter).
 *
 * No reference yet: R_ref <= 0 ohm before the first R_ref > 0 (a host that steps before its
 * inputs are connected) is an unconnected start: P_ff = 0 W, T_ref = T_room, saturated = 1,
 * one warning (the first such step only), no state change. After a reference has arrived,
 * R_ref <= 0 is refused as before.
 *
 * A wire with a data range (validity.T_data_min ...): the first step whose T_ref or load lies
 * outside it adds one warning, once per stepper.
 *
 * Saved state (feedforward_stepper_state_*): 9 + 2 n doubles, Python's None stored as NaN
 * (SMA_STATE_NONE):
 *   [0] direction (+1 / -1)          [1] previous_reference [ohm] or None
 *   [2] previous_temperature [degC] or None      [3] previous_fraction [1] or None
 *   [4] filter previous_input [W] or None        [5] filter previous_output [W] or None
 *   [6] previous_exponent [1] or None            [7] previous_slope [K] or None
 *       (the two-stage search's tangent at T_ref,k-1: Lambda and -dLambda/d(1/T_K))
 *   [8] n, the number of reversal points (0 .. memory_depth)
 *   [9 + 2 i], [10 + 2 i]  reversal i (oldest first): T [degC], xi_MF [1]
 *   anticipation > 0: then 3 doubles, the anticipation's R_ref,k-2, R_ref,k-1 and held aim
 *   [ohm] (each NaN = None)
 *   shaping "reachable": then the model wire's state, PLANT_STATE_FIXED + 2 m doubles (plant.h)
 * Python's state() dict has the same entries (its "format" is the FMI layer's header; the
 * model's is its "model" entry, the anticipation's its "anticipation" entry).
 *
 * Anticipation (feedforward_stepper_set_anticipation, runtime/anticipation.py): shaped, the
 * compensator aims L [s] ahead near the reference's lower turn, from the slope and curvature
 * of its last three samples, and holds that aim after the turn until R_ref catches up. */
#ifndef SMA_FEEDFORWARD_H
#define SMA_FEEDFORWARD_H

#include <stddef.h>

#include "constant_load.h"
#include "minor_loops.h"
#include "parameters.h"
#include "phase_lag.h"
#include "sensing.h"
#include "shaping.h"
#include "sma_message.h"

#define FEEDFORWARD_STATE_FIXED 9   /* doubles before the reversal points */
/* Python's STATE_FORMAT: the FMI layer's header names it, the doubles follow. */
#define FEEDFORWARD_STATE_FORMAT "sma-fmu compensator state 3: reversal stack, search tangent"

/* INVERSES = ("major", "minor-loop"): an inverse is its index in that tuple. */
typedef enum {
    INVERSE_MAJOR = 0,
    INVERSE_MINOR_LOOP = 1
} FeedforwardInverse;
#define INVERSE_COUNT 2
extern const char *const INVERSES[INVERSE_COUNT];

/* `inverse` ("major" or "minor-loop", exactly) -> *out; else refused ("inverse must be one of
 * major, minor-loop, got '...'"; a NULL inverse reads as Python's None). */
int require_inverse(const char *inverse, FeedforwardInverse *out, SmaMessage *message);

/* Compensator outputs for one reference sample: P_ff, feedforward power u_ff [W] (may be
 * negative); T_ref, the temperature the inverse assigns to R_ref [degC]; saturated, 1 when
 * R_ref is outside what the inverted branch reaches at the present load. */
typedef struct FeedforwardOutputs {
    double P_ff;
    double T_ref;
    int saturated;
} FeedforwardOutputs;

/* Feedforward hysteresis compensator for one wire. Holds a copy of the parameters and owns
 * its reversal stack (heap): init, use, free; a copy by value would share the stack. */
typedef struct FeedforwardStepper {
    WireParameters params;
    PhaseLagFilter filter;
    double model_load;            /* load the inverse assumes when not adapting [kg] */
    int adapt_to_load;            /* 1: the measured load enters the inverse */
    FeedforwardInverse inverse;
    FeedforwardShaping shaping;
    ReachableShaping shaper;      /* the model wire, with shaping "reachable" only */
    int direction;                /* d_ref of the last sample, +1 / -1 */
    double previous_reference;    /* R_ref of the last sample [ohm]; NaN = None */
    ReversalPoint *reversals;     /* the minor-loop memory, oldest first */
    size_t reversal_count;        /* points in use (<= params.memory_depth) */
    double previous_temperature;  /* T_ref,k-1 [degC]; NaN = None */
    double previous_fraction;     /* xi_MF,k-1 [1] the compensator assumed; NaN = None */
    TangentLine previous_line;    /* the two-stage search's tangent at T_ref,k-1; NaN = None */
    BranchCache branches;
    char warning[1024];           /* validity warning of the last step; "" = None */
    double load_before;           /* load of the last step [kg] (-inf before the first) */
    int unconnected_warned;       /* the no-reference-yet warning was given (not saved) */
    int bounded_before;           /* the last step's T_ref was bounded to T_max (not saved) */
    int data_unwarned;            /* the data-range warning is still to come (not saved) */
    double anticipation;          /* L [s]; 0: none */
    double earlier_reference;     /* the anticipation's R_ref,k-2 [ohm]; NaN = None */
    double last_reference;        /* the anticipation's R_ref,k-1 [ohm]; NaN = None */
    double held_aim;              /* the anticipated aim held after the turn [ohm]; NaN = None */
} FeedforwardStepper;

/* Python's FeedforwardStepper(params, alpha, beta, model_load, adapt_to_load, inverse,
 * shaping, power_cap). For Python's defaults pass params->phase_lag_alpha, params->beta,
 * params->model_load, "none" and NaN (None: no power cap). Refuses (in Python's order, naming
 * it) alpha < 0, beta <= 0, model_load < 0, an unknown inverse or shaping, a bad power_cap;
 * allocates the stack (memory_depth + 1 points) and, shaped, the model wire. On refusal
 * nothing is allocated and feedforward_stepper_free is harmless. */
int feedforward_stepper_init(FeedforwardStepper *self, const WireParameters *params,
                             double alpha, double beta, double model_load, int adapt_to_load,
                             const char *inverse, const char *shaping, double power_cap,
                             SmaMessage *message);
/* Python's FeedforwardStepper(..., anticipation=lead): after init, before the first step.
 * Refuses lead < 0 ("anticipation") and lead > 0 without shaping "reachable" ("anticipation =
 * ... s needs shaping 'reachable', got 'none'"); 0 leaves it off. */
int feedforward_stepper_set_anticipation(FeedforwardStepper *self, double lead,
                                         SmaMessage *message);
/* Outputs before the first step (filter in steady state); the state is unchanged.
 * Refuses after the first step, and a bad `reference` R_ref [ohm] ("R_ref") or `load` [kg]
 * ("load"); R_ref <= 0 gives the unconnected outputs. */
int feedforward_stepper_initial_outputs(FeedforwardStepper *self, double reference,
                                        double load, FeedforwardOutputs *outputs,
                                        SmaMessage *message);
/* Compensate one sample: R_ref [ohm] and load [kg] at t_k, step h [s] -> *outputs and
 * self->warning. Invalid inputs ("R_ref", "load", "step_size") and failures of the inverse
 * or the filter are refused before any state changes. R_ref <= 0 before the first R_ref > 0
 * gives the unconnected outputs and one warning. */
int feedforward_stepper_step(FeedforwardStepper *self, double reference, double load,
                             double step_size, FeedforwardOutputs *outputs,
                             SmaMessage *message);
/* Saved state, layout above. state_read checks every entry as Python's restore() does (the
 * message names the entry: direction, previous_reference, previous_temperature,
 * previous_fraction, previous_exponent, previous_slope, reversals / reversals[i],
 * previous_input, previous_output; shaped,
 * "state entry model: " and the plant's) and changes nothing when it refuses. */
size_t feedforward_stepper_state_size(const FeedforwardStepper *self);
void feedforward_stepper_state_write(const FeedforwardStepper *self, double *out);
int feedforward_stepper_state_read(FeedforwardStepper *self, const double *in, size_t count,
                                   SmaMessage *message);
/* Frees the stack; the stepper must be initialised again before use. */
void feedforward_stepper_free(FeedforwardStepper *self);

#endif
