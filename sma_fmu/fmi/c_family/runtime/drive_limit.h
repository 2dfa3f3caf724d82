/* A wire driver's current and voltage limit, and the linear driver it limits;
 * runtime/drive_limit.py.
 *
 *     P_cap(R) = min(I_max^2 R, V_max^2 / R)   [W]   (a limit of 0: none, its term +inf)
 *
 * drive_limit_apply cuts a demand to P_cap(R) (a demand <= P_cap passes unchanged). The
 * LinearDriver is the demand itself within the limit (modulation "linear").
 *
 * Saved state (linear_driver_state_*): 1 double, [0] the last step's power [W]. */
#ifndef SMA_DRIVE_LIMIT_H
#define SMA_DRIVE_LIMIT_H

#include <stddef.h>

#include "sma_message.h"

typedef struct DriveLimit {
    double I_max;            /* [A], 0: none */
    double V_max;            /* [V], 0: none */
    double current_squared;  /* I_max^2 [A^2], +inf without a current limit */
    double voltage_squared;  /* V_max^2 [V^2], +inf without a voltage limit */
    int limited;             /* a limit is set */
} DriveLimit;

/* I_max_A and V_max_V finite and >= 0, else refused naming them. */
int drive_limit_init(DriveLimit *limit, double I_max_A, double V_max_V, SmaMessage *message);

/* P_cap [W] at `resistance` [ohm] (> 0; unchecked). */
double drive_limit_cap(const DriveLimit *limit, double resistance);

/* `power` [W] cut to drive_limit_cap (unchecked). */
double drive_limit_apply(const DriveLimit *limit, double power, double resistance);

typedef struct LinearDriver {
    DriveLimit limit;
    double power;            /* the last step's power [W] */
} LinearDriver;

void linear_driver_init(LinearDriver *driver, const DriveLimit *limit);

/* P_in [W] for demand_W held over [time_s, time_s + step_size) at the wire's `resistance`:
 * non-finite demand ("P_demand") or time ("time"), a step <= 0 ("step_size") or, under a
 * limit, an R not finite and > 0 ("R") are refused; the driver is then unchanged. */
int linear_driver_step(LinearDriver *driver, double demand_W, double time_s, double step_size,
                       double resistance, double *power, SmaMessage *message);

size_t linear_driver_state_size(const LinearDriver *driver);
void linear_driver_state_write(const LinearDriver *driver, double *out);
int linear_driver_state_read(LinearDriver *driver, const double *in, size_t count,
                             SmaMessage *message);

#endif
