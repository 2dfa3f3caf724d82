/* PI feedback with anti-windup; runtime/pi_control.py (see pi_control.h). */
#include "fp_contract.h"
#include "pi_control.h"

#include <math.h>

#include "checks.h"
#include "state_entries.h"

#define PI_STATE_SIZE 1

int pi_controller_init(PIController *controller, double Kp, double Ki, SmaMessage *message)
{
    if (require_nonnegative("Kp", Kp, message) || require_nonnegative("Ki", Ki, message)) {
        return 1;
    }
    controller->Kp = Kp;
    controller->Ki = Ki;
    controller->integral = 0.0;
    return 0;
}

/* (u_raw = u_ff + Kp e + Ki I, feedback part Kp e + Ki I) [W] with the present integral. */
static double unclamped(const PIController *controller, double error, double feedforward,
                        double *feedback)
{
    *feedback = controller->Kp * error + controller->Ki * controller->integral;
    return feedforward + *feedback;
}

void pi_controller_output(const PIController *controller, double error, double feedforward,
                          double *power, double *feedback)
{
    double raw = unclamped(controller, error, feedforward, feedback);
    *power = raw < 0.0 ? 0.0 : raw;
}

void pi_controller_step(PIController *controller, double error, double feedforward,
                        double step_size, double *power, double *feedback)
{
    double raw = unclamped(controller, error, feedforward, feedback);
    int clamped = raw < 0.0;
    if (!clamped || error > 0.0) {
        controller->integral += step_size * error;
    }
    *power = clamped ? 0.0 : raw;
}

int pi_controller_sample(PIController *controller, double resistance, double reference,
                         double feedforward, double step_size, double *power, double *feedback,
                         SmaMessage *message)
{
    if (fast_finite("R", resistance, message) || fast_finite("R_ref", reference, message)
        || fast_finite("P_ff", feedforward, message)
        || fast_positive("step_size", step_size, message)) {
        return 1;
    }
    pi_controller_step(controller, resistance - reference, feedforward, step_size, power,
                       feedback);
    return 0;
}

int pi_controller_preview(const PIController *controller, double resistance, double reference,
                          double feedforward, double *power, double *feedback,
                          SmaMessage *message)
{
    if (require_finite("R", resistance, message) || require_finite("R_ref", reference, message)
        || require_finite("P_ff", feedforward, message)) {
        return 1;
    }
    pi_controller_output(controller, resistance - reference, feedforward, power, feedback);
    return 0;
}

size_t pi_controller_state_size(const PIController *controller)
{
    (void)controller;
    return PI_STATE_SIZE;
}

void pi_controller_state_write(const PIController *controller, double *out)
{
    out[0] = controller->integral;
}

int pi_controller_state_read(PIController *controller, const double *in, size_t count,
                             SmaMessage *message)
{
    if (read_entries(count, PI_STATE_SIZE, "PI state", message)
        || read_number(in[0], "integral", -HUGE_VAL, HUGE_VAL, "ohm.s", message)) {
        return 1;
    }
    controller->integral = in[0];
    return 0;
}
