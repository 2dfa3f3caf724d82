/* The controller's measurement of the wire's resistance: white noise, then an ADC's
 * quantisation; runtime/measurement.py.
 *
 *     x_k = R_k + sigma z(seed, k)                     z: standard_normal (noise.h)
 *     code_k = clip(floor(x_k / q + 1/2), 0, 2^bits - 1),   q = full_scale / 2^bits
 *     R_meas,k = code_k q                               (no quantisation when bits = 0)
 *
 * The sample index k is the sensor's count of measurements. SensedPIController is the
 * SmaPiController FMU's stepper: the PI (pi_control.h) fed by the sensor, e = R_meas - R_ref.
 *
 * Saved states: the sensor 1 double, [0] the next sample index (whole, <= 2^53);
 * the sensed PI 2 doubles, [0] integral I_k [ohm.s], [1] the sensor's next sample. */
#ifndef SMA_MEASUREMENT_H
#define SMA_MEASUREMENT_H

#include <stddef.h>
#include <stdint.h>

#include "pi_control.h"
#include "sma_message.h"

#define SENSOR_MAX_BITS 32
#define SENSOR_MAX_SEED 2147483647L   /* 2^31 - 1: an FMI 2.0 Integer */

typedef struct ResistanceSensor {
    double noise;         /* sigma [ohm RMS] */
    double full_scale;    /* [ohm] */
    int bits;             /* 0: no quantisation */
    uint64_t seed;
    double step;          /* q [ohm] */
    double levels;        /* 2^bits */
    double top;           /* 2^bits - 1, the highest code */
    int ideal;            /* no noise, no quantisation */
    uint64_t sample;      /* index of the next measurement */
} ResistanceSensor;

/* noise >= 0 and finite, bits in [0, 32], seed in [0, 2^31 - 1], full_scale >= 0 and finite
 * (> 0 with bits > 0), else refused naming it (the sensor is then untouched). */
int resistance_sensor_init(ResistanceSensor *sensor, double noise_ohm_rms, double full_scale_ohm,
                           long bits, long seed, SmaMessage *message);

/* R_meas [ohm] of the true `resistance` at sample index `sample`; no change. */
double resistance_sensor_reading(const ResistanceSensor *sensor, double resistance,
                                 uint64_t sample);

/* R_meas of the next sample into *out, then the index advances; a non-finite R ("R") is
 * refused. preview: the same reading, nothing advances. */
int resistance_sensor_measure(ResistanceSensor *sensor, double resistance, double *out,
                              SmaMessage *message);
int resistance_sensor_preview(const ResistanceSensor *sensor, double resistance, double *out,
                              SmaMessage *message);

size_t resistance_sensor_state_size(const ResistanceSensor *sensor);
void resistance_sensor_state_write(const ResistanceSensor *sensor, double *out);
int resistance_sensor_state_read(ResistanceSensor *sensor, const double *in, size_t count,
                                 SmaMessage *message);

typedef struct SensedPIController {
    PIController pi;
    ResistanceSensor sensor;
} SensedPIController;

/* One step from R, R_ref [ohm], P_ff [W], h [s], checked in that order as
 * pi_controller_sample does: (u_k, Kp e + Ki I) [W] and R_meas [ohm]. */
int sensed_pi_sample(SensedPIController *controller, double resistance, double reference,
                     double feedforward, double step_size, double *power, double *feedback,
                     double *measured, SmaMessage *message);
/* What sensed_pi_sample will give; nothing changes. */
int sensed_pi_preview(const SensedPIController *controller, double resistance, double reference,
                      double feedforward, double *power, double *feedback, double *measured,
                      SmaMessage *message);

size_t sensed_pi_state_size(const SensedPIController *controller);
void sensed_pi_state_write(const SensedPIController *controller, double *out);
int sensed_pi_state_read(SensedPIController *controller, const double *in, size_t count,
                         SmaMessage *message);

#endif
