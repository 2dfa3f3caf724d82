/*
 * combined_step.c - one call for a master's whole step: fmi2SetReal of the inputs,
 * fmi2DoStep, fmi2GetReal and fmi2GetBoolean of the outputs (sma_fmu_step).
 *
 * Not part of FMI. sma-fmu's fmpy master (sma_fmu/cosim/master.py, LeanStep) makes each of
 * its FMUs' steps through ctypes, where a call costs more than the front's work behind it;
 * one call instead of three or four saves most of that. It is nothing but the standard
 * calls in that order, made through the exported functions themselves (same checks, same
 * fast path, same statuses and messages), stopping at the first that returns above
 * fmi2Warning. A host that uses only FMI calls them itself and gets the same.
 */
#include "front.h"

EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                              const fmi2Real value[]);
EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                              fmi2Real value[]);
EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                 fmi2Boolean value[]);
EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                             fmi2Real communicationStepSize,
                             fmi2Boolean noSetFMUStatePriorToCurrentPoint);

/* What sma_fmu_step takes: filled once by the caller, who writes only t, h (and the input
 * values) before each call. ctypes spends more on each argument of a call than the front
 * spends on the whole step, so the call has one. `size` must be sizeof(SmaFmuStep). */
typedef struct {
    size_t size;
    fmi2Component component;
    const fmi2ValueReference* input_vr;
    size_t n_inputs;
    const fmi2Real* inputs;
    const fmi2ValueReference* output_vr;
    size_t n_outputs;
    fmi2Real* outputs;
    const fmi2ValueReference* flag_vr;
    size_t n_flags;
    fmi2Boolean* flags;
    fmi2Real t, h; /* [s] the communication point and step */
    int stage;     /* out: the last call made (0 fmi2SetReal, 1 fmi2DoStep, 2 fmi2GetReal,
                    * 3 fmi2GetBoolean), the one that failed if one did */
} SmaFmuStep;

/* The worst status of the calls made (see the file's comment); a call with no variables
 * (n = 0) is not made. fmi2Error for a NULL `call` or one of another size. */
EXPORT fmi2Status sma_fmu_step(SmaFmuStep* call)
{
    if (!call || call->size != sizeof(SmaFmuStep)) return fmi2Error;
    fmi2Component c = call->component;
    fmi2Status worst = fmi2OK, status;
    call->stage = 0;
    if (call->n_inputs) {
        status = fmi2SetReal(c, call->input_vr, call->n_inputs, call->inputs);
        if (status > fmi2Warning) return status;
        worst = status;
    }
    call->stage = 1;
    status = fmi2DoStep(c, call->t, call->h, fmi2True);
    if (status > fmi2Warning) return status;
    if (status > worst) worst = status;
    call->stage = 2;
    if (call->n_outputs) {
        status = fmi2GetReal(c, call->output_vr, call->n_outputs, call->outputs);
        if (status > fmi2Warning) return status;
        if (status > worst) worst = status;
    }
    if (call->n_flags) {
        call->stage = 3;
        status = fmi2GetBoolean(c, call->flag_vr, call->n_flags, call->flags);
        if (status > fmi2Warning) return status;
        if (status > worst) worst = status;
    }
    return worst;
}
