/* fmi2DoStep and the status functions: the FMI 2.0 front over the core's step
 * (core/layer_step.c). */
#include "fp_contract.h"
#include <stdio.h>

#include "fmi2_layer.h"

FMI2_Export fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                                  fmi2Real communicationStepSize,
                                  fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    ENTER;
    (void)noSetFMUStatePriorToCurrentPoint;
    return (fmi2Status)layer_step(in, "fmi2DoStep", currentCommunicationPoint,
                                  communicationStepSize);
}

FMI2_Export fmi2Status fmi2CancelStep(fmi2Component c)
{
    ENTER;
    return (fmi2Status)layer_reject(in, SMA_ERROR, "fmi2CancelStep", "illegal call: no asynchronous step is in progress");
}

FMI2_Export fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[],
                                                    size_t nu, const fmi2ValueReference z[],
                                                    size_t nz, const fmi2Real dz[], fmi2Real du[])
{
    ENTER;
    (void)u; (void)nu; (void)z; (void)nz; (void)dz; (void)du;
    return (fmi2Status)layer_reject(in, SMA_ERROR, "fmi2GetDirectionalDerivative", "not supported by this "
                        "FMU (providesDirectionalDerivative is false)");
}

FMI2_Export fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                                   size_t nvr, const fmi2Integer order[],
                                                   const fmi2Real value[])
{
    ENTER;
    (void)vr; (void)nvr; (void)order; (void)value;
    return (fmi2Status)layer_reject(in, SMA_ERROR, "fmi2SetRealInputDerivatives", "not supported by this FMU "
                        "(canInterpolateInputs is false)");
}

FMI2_Export fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                                    size_t nvr, const fmi2Integer order[],
                                                    fmi2Real value[])
{
    ENTER;
    (void)vr; (void)nvr; (void)order; (void)value;
    return (fmi2Status)layer_reject(in, SMA_ERROR, "fmi2GetRealOutputDerivatives", "not supported by this FMU "
                        "(maxOutputDerivativeOrder is 0)");
}

#define REQUIRE_STEPPED(function)                                                             \
    if (!in->stepped)                                                                         \
    return (fmi2Status)layer_reject(in, SMA_ERROR, function, "illegal call sequence: allowed only after fmi2DoStep")

FMI2_Export fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    ENTER;
    (void)s; (void)value;
    REQUIRE_STEPPED("fmi2GetStatus");
    return (fmi2Status)layer_reject(in, SMA_DISCARD, "fmi2GetStatus", "defined only while fmi2DoStep is "
                        "pending, and this FMU never returns fmi2Pending");
}

FMI2_Export fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    ENTER;
    REQUIRE_STEPPED("fmi2GetRealStatus");
    if (!value) return (fmi2Status)layer_reject(in, SMA_ERROR, "fmi2GetRealStatus", "value is NULL");
    if (s != fmi2LastSuccessfulTime)
        return (fmi2Status)layer_reject(in, SMA_DISCARD, "fmi2GetRealStatus", "only fmi2LastSuccessfulTime is defined");
    *value = in->time_defined ? in->time : in->run.start_time;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    ENTER;
    (void)s; (void)value;
    REQUIRE_STEPPED("fmi2GetIntegerStatus");
    return (fmi2Status)layer_reject(in, SMA_DISCARD, "fmi2GetIntegerStatus", "no integer status is defined");
}

FMI2_Export fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    ENTER;
    REQUIRE_STEPPED("fmi2GetBooleanStatus");
    if (!value) return (fmi2Status)layer_reject(in, SMA_ERROR, "fmi2GetBooleanStatus", "value is NULL");
    if (s != fmi2Terminated)
        return (fmi2Status)layer_reject(in, SMA_DISCARD, "fmi2GetBooleanStatus", "only fmi2Terminated is defined");
    *value = in->terminated ? fmi2True : fmi2False;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    ENTER;
    (void)s; (void)value;
    REQUIRE_STEPPED("fmi2GetStringStatus");
    return (fmi2Status)layer_reject(in, SMA_DISCARD, "fmi2GetStringStatus", "no string status is defined");
}
