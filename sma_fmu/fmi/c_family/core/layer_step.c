/* The step both fronts share (guard._do_step and the pythonfmu FMUs' front): the model-free
 * checks of t and h, the step, the discard, the validity warning, and "terminated" after the
 * very same step was discarded twice:
 *  - a bad t or h, or not following the last step: an error, nothing done;
 *  - an input the model refuses: a discard naming the input and value (never fatal); the
 *    instance stays in stepComplete, so the master may fix its inputs and retry;
 *  - a step that leaves the model's validity range: a warning with the model's warning. */
#include "fp_contract.h"
#include <math.h>
#include <stdio.h>

#include "layer.h"

/* guards._close: communication points equal up to rounding. */
static int close_to(double a, double b, double step)
{
    double scale = fabs(a) > fabs(b) ? fabs(a) : fabs(b);
    if (step > scale) scale = step;
    return fabs(a - b) <= 1e-9 * scale;
}

/* guard._do_step: 1 done, 0 not (refused: SMA_ERROR logged, or discarded). */
static SmaStatus do_step(Instance *in, const char *function, double t, double h)
{
    char a[32], b[32], e[32];
    double end, step;
    SmaMessage message;
    if (in->state != STATE_STEP_COMPLETE && !layer_allowed(in, function, IN(STATE_STEP_COMPLETE)))
        return SMA_ERROR;
    if (!(isfinite(t) && h > 0.0 && h < HUGE_VAL)) {  /* reprs only for a message: they cost us */
        layer_repr(t, a);
        layer_repr(h, b);
        layer_log(in, SMA_ERROR, "%s: currentCommunicationPoint = %s s and communicationStepSize "
                  "= %s s must be finite, the step > 0", function, a, b);
        return SMA_ERROR;
    }
    if (in->time_defined && t != in->time && !close_to(t, in->time, h)) {
        layer_repr(t, a);
        layer_repr(in->time, e);
        layer_log(in, SMA_ERROR, "%s: currentCommunicationPoint = %s s, but the last step ended at "
                  "%s s (the communication points must follow one another)", function, a, e);
        return SMA_ERROR;
    }
    end = t + h;
    if (in->stop_defined && end > in->stop_time && !close_to(end, in->stop_time, h)) {
        layer_repr(end, a);
        layer_repr(in->stop_time, e);
        layer_log(in, SMA_ERROR, "%s: the step to %s s passes stopTime = %s s", function, a, e);
        return SMA_ERROR;
    }
    step = in->model->snaps_step ? sma_nominal_step(&in->run, h) : h;
    message.text[0] = '\0';
    if (in->model->step(in->stepper, in->values, &in->run, t, step, &message)) {
        layer_repr(t, a);
        layer_log(in, SMA_DISCARD, "step at t = %s s discarded: %s", a, message.text);
        return SMA_DISCARD;
    }
    if (!layer_outputs_finite(in, in->values)) {
        in->state = STATE_ERROR;
        layer_repr(t, a);
        layer_log(in, SMA_ERROR, "%s: internal error: the step at t = %s s gave a non-finite "
                  "output; the instance is in the error state (restore a saved state or reset "
                  "it)", function, a);
        return SMA_ERROR;
    }
    in->time = end;
    in->time_defined = 1;
    layer_validity(in, function);
    return SMA_OK;
}

SmaStatus layer_step(Instance *in, const char *function, double currentCommunicationPoint,
                     double communicationStepSize)
{
    SmaStatus status;
    int same_step;
    status = layer_finish(in, do_step(in, function, currentCommunicationPoint, communicationStepSize));
    if (status > SMA_DISCARD) return status;  /* refused: nothing was stepped */
    in->stepped = 1;
    if (status != SMA_DISCARD) {
        in->terminated = in->have_discard = 0;
        return status;
    }
    same_step = in->have_discard && in->discard_time == currentCommunicationPoint &&
                in->discard_step == communicationStepSize;
    in->terminated = same_step;
    if (same_step)
        layer_plain(in, SMA_ERROR, "%s(t = %.17g s, h = %.17g s) was repeated unchanged "
                    "after a discard and discarded again: reporting %s so the master stops",
                    function, currentCommunicationPoint, communicationStepSize,
                    in->prefix[3] == '2' ? "fmi2Terminated" : "terminateSimulation");
    in->have_discard = 1;
    in->discard_time = currentCommunicationPoint;
    in->discard_step = communicationStepSize;
    return status;
}

