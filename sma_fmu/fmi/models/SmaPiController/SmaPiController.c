/* SmaPiController: the loop's PI block (anti-windup, power clamp at 0 W), native.
 *
 * A thin adapter over runtime/measurement (SensedPIController: runtime/pi_control fed through
 * the resistance sensor), as the slave beside it (sma_pi_controller.py) is over
 * runtime/measurement.py, with the same semantics: a sampled block; doStep(t_k, h) samples
 * R, R_ref and P_ff as set before the call, reads R through the sensor (noise_ohm_rms,
 * full_scale_ohm, bits, seed; all 0: R itself), its outputs then hold
 * u_k = max(0, P_ff + Kp e_k + Ki I_k) with e_k = R_measured - R_ref, and the integrator
 * advances. Before the first step the outputs are those the first step will give. Non-finite
 * inputs discard the step; invalid gains or sensor settings refuse
 * fmi2ExitInitializationMode. */
#include "fp_contract.h"
#include "measurement.h"
#include "sma_wire.h"
#include "SmaPiController_variables.h"

static int start(void *stepper, SmaValue *values, SmaRun *run, SmaMessage *message)
{
    WireParameters params;
    SensedPIController *controller = (SensedPIController *)stepper;
    double power, feedback, measured;
    if (sma_wire_parameters(&SMA_MODEL, values, run, &params, message) ||
        pi_controller_init(&controller->pi, params.Kp, params.Ki, message) ||
        resistance_sensor_init(&controller->sensor, values[VAR_noise_ohm_rms].real,
                               values[VAR_full_scale_ohm].real, values[VAR_bits].integer,
                               values[VAR_seed].integer, message) ||
        sensed_pi_preview(controller, values[VAR_R].real, values[VAR_R_ref].real,
                          values[VAR_P_ff].real, &power, &feedback, &measured, message))
        return 1;
    values[VAR_P].real = power;
    values[VAR_P_fb].real = feedback;
    values[VAR_R_measured].real = measured;
    return 0;
}

static int step(void *stepper, SmaValue *values, SmaRun *run, double time, double step_size,
                SmaMessage *message)
{
    double power, feedback, measured;
    (void)run;
    (void)time;
    if (sensed_pi_sample((SensedPIController *)stepper, values[VAR_R].real, values[VAR_R_ref].real,
                         values[VAR_P_ff].real, step_size, &power, &feedback, &measured, message))
        return 1;
    values[VAR_P].real = power;
    values[VAR_P_fb].real = feedback;
    values[VAR_R_measured].real = measured;
    return 0;
}

static size_t state_size(const void *stepper)
{
    return sensed_pi_state_size((const SensedPIController *)stepper);
}

static void state_write(const void *stepper, double *out)
{
    sensed_pi_state_write((const SensedPIController *)stepper, out);
}

static int state_read(void *stepper, const double *in, size_t count, SmaMessage *message)
{
    return sensed_pi_state_read((SensedPIController *)stepper, in, count, message);
}

const SmaModel SMA_MODEL = {
    MODEL_NAME, MODEL_GUID, "sma-fmu PI state: integral, sensor sample", LOG_CATEGORIES,
    VARIABLES, VAR_COUNT, 1, sizeof(SensedPIController), start, step, NULL, NULL, state_size,
    state_write, state_read, NULL, 0, 0, NULL, NULL, NULL};
