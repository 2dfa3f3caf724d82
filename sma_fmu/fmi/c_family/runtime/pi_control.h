/* PI feedback with a power clamp at 0 W and conditional integration (spec section 10);
 * runtime/pi_control.py.
 *
 *     e = R - R_ref (positive error -> more heat)
 *     u_raw = u_ff + Kp e_k + Ki I_k,   u = max(0, u_raw)
 *     I_(k+1) = I_k + h e_k, except while clamped (u_raw < 0) with e_k <= 0, where I stays.
 *
 * The library loop calls pi_controller_step with e_k; the SmaPiController FMU calls
 * pi_controller_sample, which checks its inputs first, and shows pi_controller_preview
 * before its first step. Python's (power, feedback) tuple is returned through `power` [W]
 * and `feedback` [W].
 *
 * Saved state (pi_controller_state_*): 1 double, [0] integral I_k [ohm.s]. */
#ifndef SMA_PI_CONTROL_H
#define SMA_PI_CONTROL_H

#include <stddef.h>

#include "sma_message.h"

/* Discrete PI with anti-windup; gains Kp [W/ohm], Ki [W/(ohm.s)]. */
typedef struct PIController {
    double Kp;         /* [W/ohm] */
    double Ki;         /* [W/(ohm.s)] */
    double integral;   /* I_k [ohm.s] */
} PIController;

/* Gains finite and >= 0, else refused naming Kp or Ki (the controller is then untouched). */
int pi_controller_init(PIController *controller, double Kp, double Ki, SmaMessage *message);

/* (power u_k, feedback Kp e + Ki I) [W] with the present integral; no change.
 * `error` e_k [ohm], `feedforward` u_ff,k [W]. */
void pi_controller_output(const PIController *controller, double error, double feedforward,
                          double *power, double *feedback);

/* As pi_controller_output, then advance the integrator by `step_size` h [s]. */
void pi_controller_step(PIController *controller, double error, double feedforward,
                        double step_size, double *power, double *feedback);

/* pi_controller_step for R [ohm], R_ref [ohm], P_ff [W] and h [s], each checked first:
 * a non-finite input or a step <= 0 is refused naming it ("R", "R_ref", "P_ff",
 * "step_size"); the state is then unchanged. */
int pi_controller_sample(PIController *controller, double resistance, double reference,
                         double feedforward, double step_size, double *power, double *feedback,
                         SmaMessage *message);

/* pi_controller_output for R [ohm], R_ref [ohm] and P_ff [W], each checked first. */
int pi_controller_preview(const PIController *controller, double resistance, double reference,
                          double feedforward, double *power, double *feedback,
                          SmaMessage *message);

size_t pi_controller_state_size(const PIController *controller);
void pi_controller_state_write(const PIController *controller, double *out);
/* Refuses (naming the entry, nothing changed) a count other than 1 or a non-finite
 * integral ("state entry integral = ..."). */
int pi_controller_state_read(PIController *controller, const double *in, size_t count,
                             SmaMessage *message);

#endif
