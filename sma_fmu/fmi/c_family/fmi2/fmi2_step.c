/* fmi2DoStep and the status functions of the native models (guard._do_step and the
 * pythonfmu FMUs' front): the model-free checks of t and h, the step, the discard, the
 * validity warning, and fmi2Terminated after the very same step was discarded twice. */
#include "fp_contract.h"
#include <math.h>
#include <stdio.h>

#include "fmi2_layer.h"

/* guards._close: communication points equal up to rounding. */
static int close_to(double a, double b, double step)
{
    double scale = fabs(a) > fabs(b) ? fabs(a) : fabs(b);
    if (step > scale) scale = step;
    return fabs(a - b) <= 1e-9 * scale;
}

/* guard._do_step: 1 done, 0 not (refused: fmi2Error logged, or discarded). */
static fmi2Status do_step(Instance *in, double t, double h)
{
    const char *function = "fmi2DoStep";
    char a[32], b[32], e[32];
    double end, step;
    SmaMessage message;
    if (in->state != STATE_STEP_COMPLETE && !layer_allowed(in, function, IN(STATE_STEP_COMPLETE)))
        return fmi2Error;
    if (!(isfinite(t) && h > 0.0 && h < HUGE_VAL)) {  /* reprs only for a message: they cost us */
        layer_repr(t, a);
        layer_repr(h, b);
        layer_log(in, fmi2Error, "%s: currentCommunicationPoint = %s s and communicationStepSize "
                  "= %s s must be finite, the step > 0", function, a, b);
        return fmi2Error;
    }
    if (in->time_defined && t != in->time && !close_to(t, in->time, h)) {
        layer_repr(t, a);
        layer_repr(in->time, e);
        layer_log(in, fmi2Error, "%s: currentCommunicationPoint = %s s, but the last step ended at "
                  "%s s (the communication points must follow one another)", function, a, e);
        return fmi2Error;
    }
    end = t + h;
    if (in->stop_defined && end > in->stop_time && !close_to(end, in->stop_time, h)) {
        layer_repr(end, a);
        layer_repr(in->stop_time, e);
        layer_log(in, fmi2Error, "%s: the step to %s s passes stopTime = %s s", function, a, e);
        return fmi2Error;
    }
    step = in->model->snaps_step ? sma_nominal_step(&in->run, h) : h;
    message.text[0] = '\0';
    if (in->model->step(in->stepper, in->values, &in->run, t, step, &message)) {
        layer_repr(t, a);
        layer_log(in, fmi2Discard, "step at t = %s s discarded: %s", a, message.text);
        return fmi2Discard;
    }
    if (!layer_outputs_finite(in, in->values)) {
        in->state = STATE_ERROR;
        layer_repr(t, a);
        layer_log(in, fmi2Error, "%s: internal error: the step at t = %s s gave a non-finite "
                  "output; the instance is in the error state (restore a saved state or reset "
                  "it)", function, a);
        return fmi2Error;
    }
    in->time = end;
    in->time_defined = 1;
    layer_validity(in, function);
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                                  fmi2Real communicationStepSize,
                                  fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    fmi2Status status;
    int same_step;
    ENTER;
    (void)noSetFMUStatePriorToCurrentPoint;
    status = layer_finish(in, do_step(in, currentCommunicationPoint, communicationStepSize));
    if (status > fmi2Discard) return status;  /* refused: nothing was stepped */
    in->stepped = 1;
    if (status != fmi2Discard) {
        in->terminated = in->have_discard = 0;
        return status;
    }
    same_step = in->have_discard && in->discard_time == currentCommunicationPoint &&
                in->discard_step == communicationStepSize;
    in->terminated = same_step;
    if (same_step)
        layer_plain(in, fmi2Error, "fmi2DoStep(t = %.17g s, h = %.17g s) was repeated unchanged "
                    "after a discard and discarded again: reporting fmi2Terminated so the master "
                    "stops", currentCommunicationPoint, communicationStepSize);
    in->have_discard = 1;
    in->discard_time = currentCommunicationPoint;
    in->discard_step = communicationStepSize;
    return status;
}

FMI2_Export fmi2Status fmi2CancelStep(fmi2Component c)
{
    ENTER;
    return layer_reject(in, fmi2Error, "fmi2CancelStep", "illegal call: no asynchronous step is in progress");
}

FMI2_Export fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[],
                                                    size_t nu, const fmi2ValueReference z[],
                                                    size_t nz, const fmi2Real dz[], fmi2Real du[])
{
    ENTER;
    (void)u; (void)nu; (void)z; (void)nz; (void)dz; (void)du;
    return layer_reject(in, fmi2Error, "fmi2GetDirectionalDerivative", "not supported by this "
                        "FMU (providesDirectionalDerivative is false)");
}

FMI2_Export fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                                   size_t nvr, const fmi2Integer order[],
                                                   const fmi2Real value[])
{
    ENTER;
    (void)vr; (void)nvr; (void)order; (void)value;
    return layer_reject(in, fmi2Error, "fmi2SetRealInputDerivatives", "not supported by this FMU "
                        "(canInterpolateInputs is false)");
}

FMI2_Export fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                                    size_t nvr, const fmi2Integer order[],
                                                    fmi2Real value[])
{
    ENTER;
    (void)vr; (void)nvr; (void)order; (void)value;
    return layer_reject(in, fmi2Error, "fmi2GetRealOutputDerivatives", "not supported by this FMU "
                        "(maxOutputDerivativeOrder is 0)");
}

#define REQUIRE_STEPPED(function)                                                             \
    if (!in->stepped)                                                                         \
    return layer_reject(in, fmi2Error, function, "illegal call sequence: allowed only after fmi2DoStep")

FMI2_Export fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    ENTER;
    (void)s; (void)value;
    REQUIRE_STEPPED("fmi2GetStatus");
    return layer_reject(in, fmi2Discard, "fmi2GetStatus", "defined only while fmi2DoStep is "
                        "pending, and this FMU never returns fmi2Pending");
}

FMI2_Export fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    ENTER;
    REQUIRE_STEPPED("fmi2GetRealStatus");
    if (!value) return layer_reject(in, fmi2Error, "fmi2GetRealStatus", "value is NULL");
    if (s != fmi2LastSuccessfulTime)
        return layer_reject(in, fmi2Discard, "fmi2GetRealStatus", "only fmi2LastSuccessfulTime is defined");
    *value = in->time_defined ? in->time : in->run.start_time;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    ENTER;
    (void)s; (void)value;
    REQUIRE_STEPPED("fmi2GetIntegerStatus");
    return layer_reject(in, fmi2Discard, "fmi2GetIntegerStatus", "no integer status is defined");
}

FMI2_Export fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    ENTER;
    REQUIRE_STEPPED("fmi2GetBooleanStatus");
    if (!value) return layer_reject(in, fmi2Error, "fmi2GetBooleanStatus", "value is NULL");
    if (s != fmi2Terminated)
        return layer_reject(in, fmi2Discard, "fmi2GetBooleanStatus", "only fmi2Terminated is defined");
    *value = in->terminated ? fmi2True : fmi2False;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    ENTER;
    (void)s; (void)value;
    REQUIRE_STEPPED("fmi2GetStringStatus");
    return layer_reject(in, fmi2Discard, "fmi2GetStringStatus", "no string status is defined");
}
