/* The FMI 3.0 functions of what these FMUs do not have (Model Exchange, clocks, derivatives,
 * dependencies): each gives fmi3Error naming itself and why (Configuration Mode:
 * fmi3_structural.c). */
#include "fp_contract.h"

#include "fmi3_layer.h"

FMI3_Export fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference, size_t* nDependencies)
{
    ENTER;
    (void)valueReference; (void)nDependencies;
    DONE(layer_reject(in, SMA_ERROR, "fmi3GetNumberOfVariableDependencies", "not supported by this FMU (no dependencies are provided)"));
}

FMI3_Export fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent, size_t elementIndicesOfDependent[], fmi3ValueReference independents[], size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[], size_t nDependencies)
{
    ENTER;
    (void)dependent; (void)elementIndicesOfDependent; (void)independents; (void)elementIndicesOfIndependents; (void)dependencyKinds; (void)nDependencies;
    DONE(layer_reject(in, SMA_ERROR, "fmi3GetVariableDependencies", "not supported by this FMU (no dependencies are provided)"));
}

FMI3_Export fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[], size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
{
    ENTER;
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed; (void)sensitivity; (void)nSensitivity;
    DONE(layer_reject(in, SMA_ERROR, "fmi3GetDirectionalDerivative", "not supported by this FMU (providesDirectionalDerivative is false)"));
}

FMI3_Export fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[], size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
{
    ENTER;
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed; (void)sensitivity; (void)nSensitivity;
    DONE(layer_reject(in, SMA_ERROR, "fmi3GetAdjointDerivative", "not supported by this FMU (providesAdjointDerivatives is false)"));
}

FMI3_Export fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[])
{
    ENTER;
    (void)valueReferences; (void)nValueReferences; (void)intervals; (void)qualifiers;
    DONE(layer_reject(in, SMA_ERROR, "fmi3GetIntervalDecimal", "not supported by this FMU (it has no clocks)"));
}

FMI3_Export fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[], fmi3IntervalQualifier qualifiers[])
{
    ENTER;
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions; (void)qualifiers;
    DONE(layer_reject(in, SMA_ERROR, "fmi3GetIntervalFraction", "not supported by this FMU (it has no clocks)"));
}

FMI3_Export fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Float64 shifts[])
{
    ENTER;
    (void)valueReferences; (void)nValueReferences; (void)shifts;
    DONE(layer_reject(in, SMA_ERROR, "fmi3GetShiftDecimal", "not supported by this FMU (it has no clocks)"));
}

FMI3_Export fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[])
{
    ENTER;
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    DONE(layer_reject(in, SMA_ERROR, "fmi3GetShiftFraction", "not supported by this FMU (it has no clocks)"));
}

FMI3_Export fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Float64 intervals[])
{
    ENTER;
    (void)valueReferences; (void)nValueReferences; (void)intervals;
    DONE(layer_reject(in, SMA_ERROR, "fmi3SetIntervalDecimal", "not supported by this FMU (it has no clocks)"));
}

FMI3_Export fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
{
    ENTER;
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    DONE(layer_reject(in, SMA_ERROR, "fmi3SetIntervalFraction", "not supported by this FMU (it has no clocks)"));
}

FMI3_Export fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Float64 shifts[])
{
    ENTER;
    (void)valueReferences; (void)nValueReferences; (void)shifts;
    DONE(layer_reject(in, SMA_ERROR, "fmi3SetShiftDecimal", "not supported by this FMU (it has no clocks)"));
}

FMI3_Export fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
{
    ENTER;
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    DONE(layer_reject(in, SMA_ERROR, "fmi3SetShiftFraction", "not supported by this FMU (it has no clocks)"));
}

FMI3_Export fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference, fmi3Float64 activationTime)
{
    ENTER;
    (void)clockReference; (void)activationTime;
    DONE(layer_reject(in, SMA_ERROR, "fmi3ActivateModelPartition", "not supported by this FMU (it has no clocks)"));
}

FMI3_Export fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance)
{
    ENTER;
    DONE(layer_reject(in, SMA_ERROR, "fmi3EvaluateDiscreteStates", "not supported by this FMU (it is a co-simulation FMU only)"));
}

FMI3_Export fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance)
{
    ENTER;
    DONE(layer_reject(in, SMA_ERROR, "fmi3EnterContinuousTimeMode", "not supported by this FMU (it is a co-simulation FMU only)"));
}

FMI3_Export fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean* enterEventMode, fmi3Boolean* terminateSimulation)
{
    ENTER;
    (void)noSetFMUStatePriorToCurrentPoint; (void)enterEventMode; (void)terminateSimulation;
    DONE(layer_reject(in, SMA_ERROR, "fmi3CompletedIntegratorStep", "not supported by this FMU (it is a co-simulation FMU only)"));
}

FMI3_Export fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time)
{
    ENTER;
    (void)time;
    DONE(layer_reject(in, SMA_ERROR, "fmi3SetTime", "not supported by this FMU (it is a co-simulation FMU only)"));
}

FMI3_Export fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[], size_t nContinuousStates)
{
    ENTER;
    (void)continuousStates; (void)nContinuousStates;
    DONE(layer_reject(in, SMA_ERROR, "fmi3SetContinuousStates", "not supported by this FMU (it is a co-simulation FMU only)"));
}

FMI3_Export fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[], size_t nContinuousStates)
{
    ENTER;
    (void)derivatives; (void)nContinuousStates;
    DONE(layer_reject(in, SMA_ERROR, "fmi3GetContinuousStateDerivatives", "not supported by this FMU (it is a co-simulation FMU only)"));
}

FMI3_Export fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[], size_t nEventIndicators)
{
    ENTER;
    (void)eventIndicators; (void)nEventIndicators;
    DONE(layer_reject(in, SMA_ERROR, "fmi3GetEventIndicators", "not supported by this FMU (it is a co-simulation FMU only)"));
}

FMI3_Export fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[], size_t nContinuousStates)
{
    ENTER;
    (void)continuousStates; (void)nContinuousStates;
    DONE(layer_reject(in, SMA_ERROR, "fmi3GetContinuousStates", "not supported by this FMU (it is a co-simulation FMU only)"));
}

FMI3_Export fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[], size_t nContinuousStates)
{
    ENTER;
    (void)nominals; (void)nContinuousStates;
    DONE(layer_reject(in, SMA_ERROR, "fmi3GetNominalsOfContinuousStates", "not supported by this FMU (it is a co-simulation FMU only)"));
}

FMI3_Export fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t* nEventIndicators)
{
    ENTER;
    (void)nEventIndicators;
    DONE(layer_reject(in, SMA_ERROR, "fmi3GetNumberOfEventIndicators", "not supported by this FMU (it is a co-simulation FMU only)"));
}

FMI3_Export fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t* nContinuousStates)
{
    ENTER;
    (void)nContinuousStates;
    DONE(layer_reject(in, SMA_ERROR, "fmi3GetNumberOfContinuousStates", "not supported by this FMU (it is a co-simulation FMU only)"));
}

FMI3_Export fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[], size_t nValues)
{
    ENTER;
    (void)valueReferences; (void)nValueReferences; (void)orders; (void)values; (void)nValues;
    DONE(layer_reject(in, SMA_ERROR, "fmi3GetOutputDerivatives", "not supported by this FMU (maxOutputDerivativeOrder is 0)"));
}
