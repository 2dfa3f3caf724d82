/* A PWM wire driver: the demanded power in, the mean power of the PWM wave over a step out;
 * runtime/pwm.py.
 *
 * The driver switches between peak_W and 0 W at frequency_Hz; periods start at t = j / f
 * (j = 0, 1, ...). At the start of each period the demanded power sets that period's duty
 * d_j = clip(P_demand / peak_W, 0, 1), the wave being on over [j/f, (j + d_j)/f), and a period
 * keeps its duty to its end. pwm_driver_step returns the exact mean of the wave over
 * [t, t + h). Times within PERIOD_TOLERANCE periods of a period start count as that start.
 * With a drive limit (pwm_driver_set_limit, drive_limit.h) the wave's on-power is peak_W cut
 * to the limit at the wire's resistance at the step's start (pwm_driver_step_limited).
 *
 * Period indices: Python's are unbounded ints; here an index is a PwmIndex, the exact integer
 * base - minus_one with base an integer-valued double and minus_one 0 or 1 (1 only beyond
 * 2^53, where base - 1 is not a double), so the driver follows Python's arithmetic exactly
 * over the whole double range.
 *
 * Saved state (pwm_driver_state_*): 4 doubles,
 *   [0] held period index base (SMA_STATE_NONE = Python's held None),
 *   [1] held index minus_one (0 or 1; 0 when none),
 *   [2] held duty [1] (SMA_STATE_NONE when none),
 *   [3] power, the last step's mean power [W]. */
#ifndef SMA_PWM_H
#define SMA_PWM_H

#include <stddef.h>

#include "drive_limit.h"
#include "sma_message.h"

#define PERIOD_TOLERANCE 1e-9    /* [periods] */
/* choice: from one period in ~11.6 days to 1 GHz, far beyond any wire driver either way */
#define MIN_FREQUENCY_HZ 1e-6
#define MAX_FREQUENCY_HZ 1e9
/* DRIVE_KINDS = ("power", "pwm") */
#define DRIVE_KIND_COUNT 2
extern const char *const DRIVE_KINDS[DRIVE_KIND_COUNT];

/* A period index j = base - minus_one (see above). */
typedef struct PwmIndex {
    double base;      /* an integer-valued double */
    int minus_one;    /* 0 or 1 */
} PwmIndex;

/* PWM of the heating power at frequency [Hz] between 0 and peak [W]. */
typedef struct PwmDriver {
    double frequency;   /* [Hz] */
    double peak;        /* [W] */
    double period;      /* 1 / frequency [s] */
    int has_held;       /* 0: Python's held None (no step yet) */
    PwmIndex held_index;  /* the period in progress at the last step's end ... */
    double held_duty;     /* ... and its duty [1] */
    double power;       /* mean power of the last step [W] */
    int limited;        /* a limit cuts the on-power (Python's limit is not None) */
    DriveLimit limit;
} PwmDriver;

/* frequency_Hz finite in [MIN_FREQUENCY_HZ, MAX_FREQUENCY_HZ], peak_W finite and > 0, else
 * refused naming it (the driver is then untouched). */
int pwm_driver_init(PwmDriver *driver, double frequency_Hz, double peak_W, SmaMessage *message);

/* Put `limit` on the on-power (one without a limit set leaves the driver unlimited). */
void pwm_driver_set_limit(PwmDriver *driver, const DriveLimit *limit);

/* The duty [1] a period starting now takes from demand_W [W]: clip(P / peak, 0, 1). */
double pwm_driver_duty_of(const PwmDriver *driver, double demand_W);

/* Mean power [W] over [time_s, time_s + step_size) with demand_W held, into *power (also
 * driver->power). Non-finite demand ("P_demand") or time ("time"), or a step <= 0
 * ("step_size") are refused; so is a time whose period index overflows a double (Python's
 * OverflowError); the driver is then unchanged. */
int pwm_driver_step(PwmDriver *driver, double demand_W, double time_s, double step_size,
                    double *power, SmaMessage *message);
/* pwm_driver_step with the wire at `resistance` [ohm], which sets the on-power under a limit
 * (refused, "R", unless finite and > 0; unused without a limit). */
int pwm_driver_step_limited(PwmDriver *driver, double demand_W, double time_s, double step_size,
                            double resistance, double *power, SmaMessage *message);

size_t pwm_driver_state_size(const PwmDriver *driver);
void pwm_driver_state_write(const PwmDriver *driver, double *out);
/* Validates as PwmDriver.restore ("held must be None or [period index, duty]", "held duty
 * must be finite / in [0, 1]", "power must be finite / in [0, peak_W]"); nothing changes
 * when it refuses. */
int pwm_driver_state_read(PwmDriver *driver, const double *in, size_t count,
                          SmaMessage *message);

#endif
