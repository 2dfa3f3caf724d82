/* SmaPwmDriver: the PWM wire driver (demanded power in, mean power of the wave out), native.
 *
 * A thin adapter over runtime/pwm (PwmDriver) and runtime/drive_limit (DriveLimit,
 * LinearDriver), as the slave beside it (sma_pwm_driver.py) is: a supply switched between
 * peak_W and 0 W at frequency_Hz, periods starting at t = j / f; doStep(t, h) holds P_demand
 * over the step and P_in then holds the exact mean of the wave over [t, t + h). The wave is
 * taken on the step grid start + k h_0: a step that starts within a millionth of a step of a
 * grid point and is h_0 long within as much is [t_k, t_k + h_0) exactly. With I_max_A or
 * V_max_V > 0 the on-power is peak_W cut to min(I_max^2 R, V_max^2 / R) at the input R;
 * modulation 2 (linear) gives P_demand itself within that limit. After initialization P_in
 * is 0 W. Invalid parameters refuse fmi2ExitInitializationMode; a non-finite P_demand (or,
 * under a limit, an R not finite and > 0) discards the step. */
#include "fp_contract.h"
#include <math.h>
#include <string.h>

#include "drive_limit.h"
#include "pwm.h"
#include "scenario_signals.h"
#include "sma_choices.h"
#include "SmaPwmDriver_variables.h"

typedef struct {
    int linear;            /* modulation "linear": the LinearDriver, else the PwmDriver */
    PwmDriver pwm;
    LinearDriver line;
} Driver;

static int start(void *stepper, SmaValue *values, SmaRun *run, SmaMessage *message)
{
    Driver *driver = (Driver *)stepper;
    DriveLimit limit;
    const char *modulation;
    (void)run;
    if (drive_limit_init(&limit, values[VAR_I_max_A].real, values[VAR_V_max_V].real, message) ||
        choice_name("modulation", values[VAR_modulation].integer, &modulation, message))
        return 1;
    driver->linear = strcmp(modulation, "linear") == 0;
    if (driver->linear) {
        linear_driver_init(&driver->line, &limit);
    } else {
        if (pwm_driver_init(&driver->pwm, values[VAR_frequency_Hz].real, values[VAR_peak_W].real,
                            message))
            return 1;
        pwm_driver_set_limit(&driver->pwm, &limit);
    }
    values[VAR_P_in].real = 0.0;
    return 0;
}

static int step(void *stepper, SmaValue *values, SmaRun *run, double time, double step_size,
                SmaMessage *message)
{
    Driver *driver = (Driver *)stepper;
    double nominal = sma_nominal_step(run, step_size), grid, power;
    if (grid_point(time, run->start_time, run->first_step, &grid) && nominal == run->first_step) {
        time = grid;
        step_size = nominal;
    }
    if (driver->linear ? linear_driver_step(&driver->line, values[VAR_P_demand].real, time,
                                            step_size, values[VAR_R].real, &power, message)
                       : pwm_driver_step_limited(&driver->pwm, values[VAR_P_demand].real, time,
                                                 step_size, values[VAR_R].real, &power, message))
        return 1;
    values[VAR_P_in].real = power;
    return 0;
}

static size_t state_size(const void *stepper)
{
    const Driver *driver = (const Driver *)stepper;
    return driver->linear ? linear_driver_state_size(&driver->line)
                          : pwm_driver_state_size(&driver->pwm);
}

static void state_write(const void *stepper, double *out)
{
    const Driver *driver = (const Driver *)stepper;
    if (driver->linear)
        linear_driver_state_write(&driver->line, out);
    else
        pwm_driver_state_write(&driver->pwm, out);
}

static int state_read(void *stepper, const double *in, size_t count, SmaMessage *message)
{
    Driver *driver = (Driver *)stepper;
    return driver->linear ? linear_driver_state_read(&driver->line, in, count, message)
                          : pwm_driver_state_read(&driver->pwm, in, count, message);
}

/* The next edge of the wave after `time` [s]: the end of the on-time of the period in
 * progress (its held duty, or the duty the present demand gives a period starting now),
 * else the next period's start. Events within PERIOD_TOLERANCE periods count as now. A
 * linear driver has none (a time <= `time`). */
static double next_event(const void *stepper, const SmaValue *values, double time)
{
    const Driver *wrapper = (const Driver *)stepper;
    const PwmDriver *driver = &wrapper->pwm;
    double k, duty, off;
    int held;
    if (wrapper->linear) return time - 1.0;
    k = floor(time / driver->period + PERIOD_TOLERANCE);
    held = driver->has_held && driver->held_index.minus_one == 0 && driver->held_index.base == k;
    duty = held ? driver->held_duty : pwm_driver_duty_of(driver, values[VAR_P_demand].real);
    off = (k + duty) * driver->period;
    if (duty > 0.0 && duty < 1.0 && off > time + PERIOD_TOLERANCE * driver->period) return off;
    return (k + 1.0) * driver->period;
}

const SmaModel SMA_MODEL = {
    MODEL_NAME, MODEL_GUID, "sma-fmu PWM state", LOG_CATEGORIES, VARIABLES, VAR_COUNT,
    0, sizeof(Driver), start, step, NULL, NULL, state_size, state_write, state_read,
    next_event,
    0, 0, NULL, NULL, NULL};
