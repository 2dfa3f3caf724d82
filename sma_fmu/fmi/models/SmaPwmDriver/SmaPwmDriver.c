/* SmaPwmDriver: the PWM wire driver (demanded power in, mean power of the wave out), native.
 *
 * A thin adapter over runtime/pwm (PwmDriver), as the slave beside it (sma_pwm_driver.py) is: a supply
 * switched between peak_W and 0 W at frequency_Hz, periods starting at t = j / f; doStep(t, h)
 * holds P_demand over the step and P_in then holds the exact mean of the wave over
 * [t, t + h). The wave is taken on the step grid start + k h_0: a step that starts within a
 * millionth of a step of a grid point and is h_0 long within as much is [t_k, t_k + h_0)
 * exactly. After initialization P_in is 0 W. Invalid parameters refuse
 * fmi2ExitInitializationMode; a non-finite P_demand discards the step. */
#include "fp_contract.h"
#include <math.h>

#include "pwm.h"
#include "scenario_signals.h"
#include "SmaPwmDriver_variables.h"

static int start(void *stepper, SmaValue *values, SmaRun *run, SmaMessage *message)
{
    (void)run;
    if (pwm_driver_init((PwmDriver *)stepper, values[VAR_frequency_Hz].real,
                        values[VAR_peak_W].real, message))
        return 1;
    values[VAR_P_in].real = 0.0;
    return 0;
}

static int step(void *stepper, SmaValue *values, SmaRun *run, double time, double step_size,
                SmaMessage *message)
{
    double nominal = sma_nominal_step(run, step_size), grid, power;
    if (grid_point(time, run->start_time, run->first_step, &grid) && nominal == run->first_step) {
        time = grid;
        step_size = nominal;
    }
    if (pwm_driver_step((PwmDriver *)stepper, values[VAR_P_demand].real, time, step_size, &power,
                        message))
        return 1;
    values[VAR_P_in].real = power;
    return 0;
}

static size_t state_size(const void *stepper)
{
    return pwm_driver_state_size((const PwmDriver *)stepper);
}

static void state_write(const void *stepper, double *out)
{
    pwm_driver_state_write((const PwmDriver *)stepper, out);
}

static int state_read(void *stepper, const double *in, size_t count, SmaMessage *message)
{
    return pwm_driver_state_read((PwmDriver *)stepper, in, count, message);
}

/* The next edge of the wave after `time` [s]: the end of the on-time of the period in
 * progress (its held duty, or the duty the present demand gives a period starting now),
 * else the next period's start. Events within PERIOD_TOLERANCE periods count as now. */
static double next_event(const void *stepper, const SmaValue *values, double time)
{
    const PwmDriver *driver = (const PwmDriver *)stepper;
    double k = floor(time / driver->period + PERIOD_TOLERANCE), duty, off;
    int held = driver->has_held && driver->held_index.minus_one == 0 && driver->held_index.base == k;
    duty = held ? driver->held_duty : pwm_driver_duty_of(driver, values[VAR_P_demand].real);
    off = (k + duty) * driver->period;
    if (duty > 0.0 && duty < 1.0 && off > time + PERIOD_TOLERANCE * driver->period) return off;
    return (k + 1.0) * driver->period;
}

const SmaModel SMA_MODEL = {
    MODEL_NAME, MODEL_GUID, "sma-fmu PWM state", LOG_CATEGORIES, VARIABLES, VAR_COUNT,
    0, sizeof(PwmDriver), start, step, NULL, NULL, state_size, state_write, state_read,
    next_event,
    0, 0, NULL, NULL, NULL};
