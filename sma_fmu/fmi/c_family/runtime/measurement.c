/* The resistance sensor and the PI it feeds; runtime/measurement.py (see measurement.h). */
#include "fp_contract.h"
#include "measurement.h"

#include <math.h>

#include "checks.h"
#include "noise.h"
#include "state_entries.h"

#define MAX_SAMPLE 9007199254740992.0   /* 2^53: a sample index a double holds exactly */

static int whole(const char *name, long value, long low, long high, SmaMessage *message)
{
    if (value < low || value > high) {
        return sma_message_set(message, "%s must be a whole number in [%ld, %ld], got %ld", name,
                               low, high, value);
    }
    return 0;
}

int resistance_sensor_init(ResistanceSensor *sensor, double noise_ohm_rms, double full_scale_ohm,
                           long bits, long seed, SmaMessage *message)
{
    if (require_nonnegative("noise_ohm_rms", noise_ohm_rms, message)
        || whole("bits", bits, 0, SENSOR_MAX_BITS, message)
        || whole("seed", seed, 0, SENSOR_MAX_SEED, message)
        || require_nonnegative("full_scale_ohm", full_scale_ohm, message)) {
        return 1;
    }
    if (bits && !(full_scale_ohm > 0.0)) {
        return sma_message_set(message, "full_scale_ohm must be > 0 with bits = %ld, got %.17g",
                               bits, full_scale_ohm);
    }
    sensor->noise = noise_ohm_rms;
    sensor->bits = (int)bits;
    sensor->seed = (uint64_t)seed;
    sensor->full_scale = full_scale_ohm;
    sensor->levels = ldexp(1.0, (int)bits);
    sensor->step = bits ? full_scale_ohm / sensor->levels : 0.0;
    sensor->top = sensor->levels - 1.0;
    sensor->ideal = noise_ohm_rms == 0.0 && bits == 0;
    sensor->sample = 0;
    return 0;
}

double resistance_sensor_reading(const ResistanceSensor *sensor, double resistance,
                                 uint64_t sample)
{
    double value = resistance, scaled, code;
    if (sensor->noise != 0.0) {
        value = resistance + sensor->noise * standard_normal(sensor->seed, sample);
    }
    if (sensor->bits) {   /* floor(x/q + 1/2) clipped to [0, top], compared before the floor */
        scaled = value / sensor->step + 0.5;
        code = scaled < 1.0 ? 0.0 : (scaled >= sensor->levels ? sensor->top : floor(scaled));
        value = code * sensor->step;
    }
    return value;
}

int resistance_sensor_measure(ResistanceSensor *sensor, double resistance, double *out,
                              SmaMessage *message)
{
    if (fast_finite("R", resistance, message)) {
        return 1;
    }
    *out = resistance_sensor_reading(sensor, resistance, sensor->sample);
    sensor->sample++;
    return 0;
}

int resistance_sensor_preview(const ResistanceSensor *sensor, double resistance, double *out,
                              SmaMessage *message)
{
    if (require_finite("R", resistance, message)) {
        return 1;
    }
    *out = resistance_sensor_reading(sensor, resistance, sensor->sample);
    return 0;
}

size_t resistance_sensor_state_size(const ResistanceSensor *sensor)
{
    (void)sensor;
    return 1;
}

void resistance_sensor_state_write(const ResistanceSensor *sensor, double *out)
{
    out[0] = (double)sensor->sample;
}

/* The saved sample index, checked as ResistanceSensor.restore does. */
static int read_sample(double value, uint64_t *sample, SmaMessage *message)
{
    if (!(value >= 0.0 && value <= MAX_SAMPLE && value == floor(value))) {
        return sma_message_set(message, "state entry sample must be a whole number in [0, 2^53], "
                               "got %.17g", value);
    }
    *sample = (uint64_t)value;
    return 0;
}

int resistance_sensor_state_read(ResistanceSensor *sensor, const double *in, size_t count,
                                 SmaMessage *message)
{
    uint64_t sample = 0;
    if (read_entries(count, 1, "sensor state", message) || read_sample(in[0], &sample, message)) {
        return 1;
    }
    sensor->sample = sample;
    return 0;
}

int sensed_pi_sample(SensedPIController *controller, double resistance, double reference,
                     double feedforward, double step_size, double *power, double *feedback,
                     double *measured, SmaMessage *message)
{
    if (fast_finite("R", resistance, message) || fast_finite("R_ref", reference, message)
        || fast_finite("P_ff", feedforward, message)
        || fast_positive("step_size", step_size, message)) {
        return 1;
    }
    *measured = resistance_sensor_reading(&controller->sensor, resistance,
                                          controller->sensor.sample);
    controller->sensor.sample++;
    pi_controller_step(&controller->pi, *measured - reference, feedforward, step_size, power,
                       feedback);
    return 0;
}

int sensed_pi_preview(const SensedPIController *controller, double resistance, double reference,
                      double feedforward, double *power, double *feedback, double *measured,
                      SmaMessage *message)
{
    double reading;
    if (resistance_sensor_preview(&controller->sensor, resistance, &reading, message)
        || pi_controller_preview(&controller->pi, reading, reference, feedforward, power,
                                 feedback, message)) {
        return 1;
    }
    *measured = reading;
    return 0;
}

size_t sensed_pi_state_size(const SensedPIController *controller)
{
    (void)controller;
    return 2;
}

void sensed_pi_state_write(const SensedPIController *controller, double *out)
{
    out[0] = controller->pi.integral;
    out[1] = (double)controller->sensor.sample;
}

int sensed_pi_state_read(SensedPIController *controller, const double *in, size_t count,
                         SmaMessage *message)
{
    uint64_t sample = 0;
    if (read_entries(count, 2, "PI state", message)
        || read_number(in[0], "integral", -HUGE_VAL, HUGE_VAL, "ohm.s", message)
        || read_sample(in[1], &sample, message)) {
        return 1;
    }
    controller->pi.integral = in[0];
    controller->sensor.sample = sample;
    return 0;
}
