/* SmaPiController: the loop's PI block (anti-windup, power clamp at 0 W), native.
 *
 * A thin adapter over runtime/pi_control (PIController), as the slave beside it (sma_pi_controller.py)
 * is over runtime/pi_control.py, with the same semantics: a sampled block; doStep(t_k, h)
 * samples R, R_ref and P_ff as set before the call, its outputs then hold
 * u_k = max(0, P_ff + Kp e_k + Ki I_k) with e_k = R - R_ref, and the integrator advances.
 * Before the first step the outputs are those the first step will give. Non-finite inputs
 * discard the step; invalid gains refuse fmi2ExitInitializationMode. */
#include "fp_contract.h"
#include "pi_control.h"
#include "sma_wire.h"
#include "SmaPiController_variables.h"

static int start(void *stepper, SmaValue *values, SmaRun *run, SmaMessage *message)
{
    WireParameters params;
    PIController *controller = (PIController *)stepper;
    double power, feedback;
    if (sma_wire_parameters(&SMA_MODEL, values, run, &params, message) ||
        pi_controller_init(controller, params.Kp, params.Ki, message) ||
        pi_controller_preview(controller, values[VAR_R].real, values[VAR_R_ref].real,
                              values[VAR_P_ff].real, &power, &feedback, message))
        return 1;
    values[VAR_P].real = power;
    values[VAR_P_fb].real = feedback;
    return 0;
}

static int step(void *stepper, SmaValue *values, SmaRun *run, double time, double step_size,
                SmaMessage *message)
{
    double power, feedback;
    (void)run;
    (void)time;
    if (pi_controller_sample((PIController *)stepper, values[VAR_R].real, values[VAR_R_ref].real,
                             values[VAR_P_ff].real, step_size, &power, &feedback, message))
        return 1;
    values[VAR_P].real = power;
    values[VAR_P_fb].real = feedback;
    return 0;
}

static size_t state_size(const void *stepper)
{
    return pi_controller_state_size((const PIController *)stepper);
}

static void state_write(const void *stepper, double *out)
{
    pi_controller_state_write((const PIController *)stepper, out);
}

static int state_read(void *stepper, const double *in, size_t count, SmaMessage *message)
{
    return pi_controller_state_read((PIController *)stepper, in, count, message);
}

const SmaModel SMA_MODEL = {
    MODEL_NAME, MODEL_GUID, "sma-fmu PI state: integral", LOG_CATEGORIES, VARIABLES, VAR_COUNT,
    1, sizeof(PIController), start, step, NULL, NULL, state_size, state_write, state_read, NULL,
    0, 0, NULL, NULL, NULL};
