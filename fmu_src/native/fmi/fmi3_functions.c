/* FMI 3.0 co-simulation and Model Exchange entry points over the shared core (fmu_instance.c).
 *
 * The model is initialised at the startTime given to fmi3EnterInitializationMode. Misuse returns
 * fmi3Error with a logged reason (the instance then accepts only get, reset, free and set FMU
 * state); a refused step returns fmi3Discard with the model unchanged, lastSuccessfulTime =
 * currentCommunicationPoint and terminateSimulation true (the same step would be refused again, so
 * the importer stops; one that corrects its inputs may step again). The independent variable ``time``
 * has the value reference after the spec's variables. Model Exchange: fmu_model_exchange.c; directional and
 * adjoint derivatives: fmu_derivatives.c. Functions of the scheduled execution interface, clocks and output
 * derivatives are exported, as the standard requires, and return fmi3Error (instantiation: NULL).
 */
#include <stddef.h>

#include "fmi3Functions.h"
#include "fmu_instance.h"

static void emit(const Instance *instance, Status status, const char *category, const char *message)
{
    fmi3LogMessageCallback logger = (fmi3LogMessageCallback)instance->host_logger;
    if (logger != NULL) {
        logger(instance->host_environment, (fmi3Status)status, category, message);
    }
}

/* Scalar variables only: one value per value reference. */
static int counts_match(Instance *instance, const char *function, size_t nvr, size_t nValues)
{
    if (nvr != nValues) {
        instance_fail(instance, "fmi3", function, ": nValues differs from nValueReferences (scalar variables only)",
                      (const char *)NULL);
        return 0;
    }
    return 1;
}

const char *fmi3GetVersion(void)
{
    return fmi3Version;
}

fmi3Status fmi3SetDebugLogging(fmi3Instance c, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[])
ON_INSTANCE(fmi3, instance_set_debug_logging(instance, "SetDebugLogging", loggingOn != fmi3False, nCategories,
                                             categories))

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible UNUSED,
                                          fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage)
{
    Instance *instance = instance_new(instanceName, instantiationToken, "fmi3", emit, (void (*)(void))logMessage,
                                      instanceEnvironment, resourcePath);
    if (instance != NULL) {
        instance->model_exchange = 1;
        instance->logging_on = loggingOn != fmi3False;
    }
    return instance;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible UNUSED,
                                         fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed UNUSED, fmi3Boolean earlyReturnAllowed UNUSED,
                                         const fmi3ValueReference requiredIntermediateVariables[] UNUSED,
                                         size_t nRequiredIntermediateVariables UNUSED,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate UNUSED)
{
    /* resourcePath: the resources folder (a path; NULL: none); eventModeUsed: these models have no
     * clocks or events; loggingOn: a message of status OK (information) is logged only with it, the others
     * always */
    Instance *instance = instance_new(instanceName, instantiationToken, "fmi3", emit, (void (*)(void))logMessage,
                                      instanceEnvironment, resourcePath);
    if (instance != NULL) {
        instance->logging_on = loggingOn != fmi3False;
    }
    return instance;
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName UNUSED, fmi3String instantiationToken UNUSED,
                                               fmi3String resourcePath UNUSED, fmi3Boolean visible UNUSED,
                                               fmi3Boolean loggingOn UNUSED,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage,
                                               fmi3ClockUpdateCallback clockUpdate UNUSED,
                                               fmi3LockPreemptionCallback lockPreemption UNUSED,
                                               fmi3UnlockPreemptionCallback unlockPreemption UNUSED)
{
    if (logMessage != NULL) {
        logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                   "fmi3InstantiateScheduledExecution: this FMU offers co-simulation only");
    }
    return NULL;
}

void fmi3FreeInstance(fmi3Instance c)
{
    instance_free((Instance *)c);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance c, fmi3Boolean toleranceDefined UNUSED,
                                       fmi3Float64 tolerance UNUSED,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined UNUSED,
                                       fmi3Float64 stopTime UNUSED)
{
    INSTANCE(c, fmi3Error)
    if (!instance_allows(instance, MODE_BIT(MODE_INSTANTIATED), "EnterInitializationMode") ||
        instance_set_start_time(instance, "EnterInitializationMode", startTime) != STATUS_OK) {
        return fmi3Error;
    }
    instance->mode = MODE_INITIALIZATION;
    return fmi3OK;
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance c)
ON_INSTANCE(fmi3, instance_exit_initialization(instance))

fmi3Status fmi3EnterEventMode(fmi3Instance c)
ON_INSTANCE(fmi3, model_exchange_enter_mode(instance, "EnterEventMode", 1))

fmi3Status fmi3Terminate(fmi3Instance c)
ON_INSTANCE(fmi3, instance_terminate(instance))

fmi3Status fmi3Reset(fmi3Instance c)
ON_INSTANCE(fmi3, instance_reset(instance))

/* ---- values ------------------------------------------------------------------------------- */

fmi3Status fmi3GetFloat64(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 values[],
                          size_t nValues)
ON_INSTANCE(fmi3, counts_match(instance, "GetFloat64", nvr, nValues)
                  ? instance_get_real(instance, "GetFloat64", vr, nvr, values) : STATUS_ERROR)

fmi3Status fmi3SetFloat64(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Float64 values[],
                          size_t nValues)
ON_INSTANCE(fmi3, counts_match(instance, "SetFloat64", nvr, nValues)
                  ? instance_set_real(instance, "SetFloat64", vr, nvr, values) : STATUS_ERROR)

fmi3Status fmi3GetInt32(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Int32 values[], size_t nValues)
ON_INSTANCE(fmi3, counts_match(instance, "GetInt32", nvr, nValues)
                  ? instance_get_integer(instance, "GetInt32", vr, nvr, values) : STATUS_ERROR)

fmi3Status fmi3SetInt32(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Int32 values[],
                        size_t nValues)
ON_INSTANCE(fmi3, counts_match(instance, "SetInt32", nvr, nValues)
                  ? instance_set_integer(instance, "SetInt32", vr, nvr, values) : STATUS_ERROR)

/* The types no variable of these models has: every reference is refused by name. */
#define NO_VARIABLES_OF(Type, CType)                                                                                \
    fmi3Status fmi3Get##Type(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, CType values[] UNUSED,      \
                             size_t nValues)                                                                        \
    ON_INSTANCE(fmi3, counts_match(instance, "Get" #Type, nvr, nValues)                                             \
                      ? instance_no_variables_of(instance, "Get" #Type, vr, nvr, #Type, 0) : STATUS_ERROR)          \
    fmi3Status fmi3Set##Type(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,                             \
                             const CType values[] UNUSED, size_t nValues)                                           \
    ON_INSTANCE(fmi3, counts_match(instance, "Set" #Type, nvr, nValues)                                             \
                      ? instance_no_variables_of(instance, "Set" #Type, vr, nvr, #Type, 1) : STATUS_ERROR)

NO_VARIABLES_OF(Float32, fmi3Float32)
NO_VARIABLES_OF(Int8, fmi3Int8)
NO_VARIABLES_OF(UInt8, fmi3UInt8)
NO_VARIABLES_OF(Int16, fmi3Int16)
NO_VARIABLES_OF(UInt16, fmi3UInt16)
NO_VARIABLES_OF(UInt32, fmi3UInt32)
NO_VARIABLES_OF(Int64, fmi3Int64)
NO_VARIABLES_OF(UInt64, fmi3UInt64)

fmi3Status fmi3GetBoolean(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Boolean values[],
                          size_t nValues)
ON_INSTANCE(fmi3, counts_match(instance, "GetBoolean", nvr, nValues)
                  ? instance_get_boolean(instance, "GetBoolean", vr, nvr, values, sizeof(fmi3Boolean)) : STATUS_ERROR)

fmi3Status fmi3SetBoolean(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Boolean values[],
                          size_t nValues)
ON_INSTANCE(fmi3, counts_match(instance, "SetBoolean", nvr, nValues)
                  ? instance_set_boolean(instance, "SetBoolean", vr, nvr, values, sizeof(fmi3Boolean)) : STATUS_ERROR)

fmi3Status fmi3GetString(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3String values[],
                         size_t nValues)
ON_INSTANCE(fmi3, counts_match(instance, "GetString", nvr, nValues)
                  ? instance_get_string(instance, "GetString", vr, nvr, values) : STATUS_ERROR)

fmi3Status fmi3SetString(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3String values[],
                         size_t nValues)
ON_INSTANCE(fmi3, counts_match(instance, "SetString", nvr, nValues)
                  ? instance_set_string(instance, "SetString", vr, nvr, values) : STATUS_ERROR)

fmi3Status fmi3GetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, size_t valueSizes[] UNUSED,
                         fmi3Binary values[] UNUSED, size_t nValues UNUSED)
ON_INSTANCE(fmi3, instance_no_variables_of(instance, "GetBinary", vr, nvr, "Binary", 0))

fmi3Status fmi3SetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const size_t valueSizes[] UNUSED,
                         const fmi3Binary values[] UNUSED, size_t nValues UNUSED)
ON_INSTANCE(fmi3, instance_no_variables_of(instance, "SetBinary", vr, nvr, "Binary", 1))

fmi3Status fmi3GetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Clock values[] UNUSED)
ON_INSTANCE(fmi3, instance_no_variables_of(instance, "GetClock", vr, nvr, "Clock", 0))

fmi3Status fmi3SetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Clock values[] UNUSED)
ON_INSTANCE(fmi3, instance_no_variables_of(instance, "SetClock", vr, nvr, "Clock", 1))

/* ---- FMU state ---------------------------------------------------------------------------- */

FMU_STATE_FUNCTIONS(fmi3, fmi3Instance, FMUState, Deserialize)

/* ---- stepping ----------------------------------------------------------------------------- */

fmi3Status fmi3DoStep(fmi3Instance c, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint UNUSED, fmi3Boolean *eventHandlingNeeded,
                      fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime)
{
    Status status;
    INSTANCE(c, fmi3Error)
    if (!instance_is(instance, 0, "DoStep") || !instance_allows(instance, MODE_BIT(MODE_STEP), "DoStep")) {
        return fmi3Error;
    }
    if (eventHandlingNeeded == NULL || terminateSimulation == NULL || earlyReturn == NULL ||
        lastSuccessfulTime == NULL) {
        return (fmi3Status)instance_fail(instance, "fmi3DoStep: null output argument", (const char *)NULL);
    }
    status = instance_do_step(instance, currentCommunicationPoint, communicationStepSize);
    *eventHandlingNeeded = fmi3False;
    *terminateSimulation = status == STATUS_DISCARD ? fmi3True : fmi3False; /* retrying gets the same refusal */
    *earlyReturn = fmi3False;
    *lastSuccessfulTime = status == STATUS_OK ? instance->data.time : currentCommunicationPoint;
    return (fmi3Status)status;
}

/* ---- derivatives (fmu_derivatives.c); what an FMU without events or clocks does not offer ------ */

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance c, fmi3ValueReference valueReference UNUSED,
                                               size_t *nDependencies UNUSED)
ON_INSTANCE(fmi3, instance_unsupported(instance, "GetNumberOfVariableDependencies"))

fmi3Status fmi3GetVariableDependencies(fmi3Instance c, fmi3ValueReference dependent UNUSED,
                                       size_t elementIndicesOfDependent[] UNUSED,
                                       fmi3ValueReference independents[] UNUSED,
                                       size_t elementIndicesOfIndependents[] UNUSED,
                                       fmi3DependencyKind dependencyKinds[] UNUSED,
                                       size_t nDependencies UNUSED)
ON_INSTANCE(fmi3, instance_unsupported(instance, "GetVariableDependencies"))

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance c, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
ON_INSTANCE(fmi3, derivatives_get(instance, "GetDirectionalDerivative", unknowns, nUnknowns, knowns, nKnowns, seed,
                                  nSeed, sensitivity, nSensitivity, 0))

fmi3Status fmi3GetAdjointDerivative(fmi3Instance c, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
ON_INSTANCE(fmi3, derivatives_get(instance, "GetAdjointDerivative", unknowns, nUnknowns, knowns, nKnowns, seed,
                                  nSeed, sensitivity, nSensitivity, 1))

fmi3Status fmi3EnterConfigurationMode(fmi3Instance c)
ON_INSTANCE(fmi3, instance_unsupported(instance, "EnterConfigurationMode"))

fmi3Status fmi3ExitConfigurationMode(fmi3Instance c)
ON_INSTANCE(fmi3, instance_unsupported(instance, "ExitConfigurationMode"))

fmi3Status fmi3GetIntervalDecimal(fmi3Instance c, const fmi3ValueReference vr[] UNUSED, size_t nvr UNUSED,
                                  fmi3Float64 intervals[] UNUSED,
                                  fmi3IntervalQualifier qualifiers[] UNUSED)
ON_INSTANCE(fmi3, instance_unsupported(instance, "GetIntervalDecimal"))

fmi3Status fmi3GetIntervalFraction(fmi3Instance c, const fmi3ValueReference vr[] UNUSED, size_t nvr UNUSED,
                                   fmi3UInt64 counters[] UNUSED,
                                   fmi3UInt64 resolutions[] UNUSED, fmi3IntervalQualifier qualifiers[] UNUSED)
ON_INSTANCE(fmi3, instance_unsupported(instance, "GetIntervalFraction"))

fmi3Status fmi3GetShiftDecimal(fmi3Instance c, const fmi3ValueReference vr[] UNUSED, size_t nvr UNUSED,
                               fmi3Float64 shifts[] UNUSED)
ON_INSTANCE(fmi3, instance_unsupported(instance, "GetShiftDecimal"))

fmi3Status fmi3GetShiftFraction(fmi3Instance c, const fmi3ValueReference vr[] UNUSED, size_t nvr UNUSED,
                                fmi3UInt64 counters[] UNUSED,
                                fmi3UInt64 resolutions[] UNUSED)
ON_INSTANCE(fmi3, instance_unsupported(instance, "GetShiftFraction"))

fmi3Status fmi3SetIntervalDecimal(fmi3Instance c, const fmi3ValueReference vr[] UNUSED, size_t nvr UNUSED,
                                  const fmi3Float64 intervals[] UNUSED)
ON_INSTANCE(fmi3, instance_unsupported(instance, "SetIntervalDecimal"))

fmi3Status fmi3SetIntervalFraction(fmi3Instance c, const fmi3ValueReference vr[] UNUSED, size_t nvr UNUSED,
                                   const fmi3UInt64 counters[] UNUSED, const fmi3UInt64 resolutions[] UNUSED)
ON_INSTANCE(fmi3, instance_unsupported(instance, "SetIntervalFraction"))

fmi3Status fmi3SetShiftDecimal(fmi3Instance c, const fmi3ValueReference vr[] UNUSED, size_t nvr UNUSED,
                               const fmi3Float64 shifts[] UNUSED)
ON_INSTANCE(fmi3, instance_unsupported(instance, "SetShiftDecimal"))

fmi3Status fmi3SetShiftFraction(fmi3Instance c, const fmi3ValueReference vr[] UNUSED, size_t nvr UNUSED,
                                const fmi3UInt64 counters[] UNUSED, const fmi3UInt64 resolutions[] UNUSED)
ON_INSTANCE(fmi3, instance_unsupported(instance, "SetShiftFraction"))

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance c)
ON_INSTANCE(fmi3, instance_unsupported(instance, "EvaluateDiscreteStates"))

/* No events: nothing to update, no next event. */
fmi3Status fmi3UpdateDiscreteStates(fmi3Instance c, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime)
{
    INSTANCE(c, fmi3Error)
    if (!model_exchange_call(instance, "UpdateDiscreteStates",
                             discreteStatesNeedUpdate != NULL && terminateSimulation != NULL &&
                                 nominalsOfContinuousStatesChanged != NULL && valuesOfContinuousStatesChanged != NULL &&
                                 nextEventTimeDefined != NULL && nextEventTime != NULL,
                             1)) {
        return fmi3Error;
    }
    *discreteStatesNeedUpdate = fmi3False;
    *terminateSimulation = fmi3False;
    *nominalsOfContinuousStatesChanged = fmi3False;
    *valuesOfContinuousStatesChanged = fmi3False;
    *nextEventTimeDefined = fmi3False;
    *nextEventTime = 0.0;
    return fmi3OK;
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance c)
ON_INSTANCE(fmi3, model_exchange_enter_mode(instance, "EnterContinuousTimeMode", 0))

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance c, fmi3Boolean noSetFMUStatePriorToCurrentPoint UNUSED,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation)
{
    INSTANCE(c, fmi3Error)
    if (!model_exchange_call(instance, "CompletedIntegratorStep",
                             enterEventMode != NULL && terminateSimulation != NULL, 0)) {
        return fmi3Error;
    }
    *enterEventMode = fmi3False;
    *terminateSimulation = fmi3False;
    return fmi3OK;
}

fmi3Status fmi3SetTime(fmi3Instance c, fmi3Float64 time)
ON_INSTANCE(fmi3, model_exchange_set_time(instance, "SetTime", time))

fmi3Status fmi3SetContinuousStates(fmi3Instance c, const fmi3Float64 continuousStates[], size_t nContinuousStates)
ON_INSTANCE(fmi3, model_exchange_set_states(instance, "SetContinuousStates", continuousStates, nContinuousStates))

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance c, fmi3Float64 derivatives[], size_t nContinuousStates)
ON_INSTANCE(fmi3, model_exchange_get_derivatives(instance, "GetContinuousStateDerivatives", derivatives,
                                                 nContinuousStates))

fmi3Status fmi3GetEventIndicators(fmi3Instance c, fmi3Float64 eventIndicators[] UNUSED, size_t nEventIndicators)
ON_INSTANCE(fmi3, model_exchange_get_event_indicators(instance, "GetEventIndicators", nEventIndicators))

fmi3Status fmi3GetContinuousStates(fmi3Instance c, fmi3Float64 continuousStates[], size_t nContinuousStates)
ON_INSTANCE(fmi3, model_exchange_get_states(instance, "GetContinuousStates", continuousStates, nContinuousStates))

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance c, fmi3Float64 nominals[], size_t nContinuousStates)
ON_INSTANCE(fmi3, model_exchange_get_nominals(instance, "GetNominalsOfContinuousStates", nominals, nContinuousStates))

static fmi3Status count(Instance *instance, const char *function, size_t *number, size_t value)
{
    if (!instance_is(instance, 1, function)) {
        return fmi3Error;
    }
    if (number == NULL) {
        return (fmi3Status)instance_fail(instance, "fmi3", function, ": null output argument", (const char *)NULL);
    }
    *number = value;
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance c, size_t *nEventIndicators)
ON_INSTANCE(fmi3, count(instance, "GetNumberOfEventIndicators", nEventIndicators, 0))

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance c, size_t *nContinuousStates)
ON_INSTANCE(fmi3, count(instance, "GetNumberOfContinuousStates", nContinuousStates, MODEL_STATE_COUNT))

fmi3Status fmi3EnterStepMode(fmi3Instance c)
ON_INSTANCE(fmi3, instance_unsupported(instance, "EnterStepMode"))

fmi3Status fmi3GetOutputDerivatives(fmi3Instance c, const fmi3ValueReference vr[] UNUSED, size_t nvr UNUSED,
                                    const fmi3Int32 orders[] UNUSED, fmi3Float64 values[] UNUSED,
                                    size_t nValues UNUSED)
ON_INSTANCE(fmi3, instance_unsupported(instance, "GetOutputDerivatives"))

fmi3Status fmi3ActivateModelPartition(fmi3Instance c, fmi3ValueReference clockReference UNUSED,
                                      fmi3Float64 activationTime UNUSED)
ON_INSTANCE(fmi3, instance_unsupported(instance, "ActivateModelPartition"))
