/* FMI 2.0 co-simulation and Model Exchange entry points over the shared core (fmu_instance.c,
 * fmu_model_exchange.c).
 *
 * Calls out of sequence, unknown value references, wrong types and bad FMU states return
 * fmi2Error with a logged reason (the instance then accepts only get, reset, free and set FMU
 * state, as the standard says); a refused step returns fmi2Discard with the model unchanged and
 * fmi2Terminated true: the same step would be refused again, so a master that retries a discarded
 * step (fmusim, fmpy) stops; one that corrects its inputs may step again. Messages reach
 * the logger as data: its format argument is always "%s".
 */
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmu_instance.h"

/* FMI2_FUNCTION_PREFIX prefixes the entry points (several FMUs linked into one program), as the
 * standard's fmi2Functions.h does; some copies of that header (fmpy's) leave it out. */
#ifdef FMI2_FUNCTION_PREFIX
#undef fmi2FullName
#define fmi2PrefixPaste(a, b) a##b
#define fmi2PrefixName(a, b) fmi2PrefixPaste(a, b)
#define fmi2FullName(name) fmi2PrefixName(FMI2_FUNCTION_PREFIX, name)
#endif

static void emit(const Instance *instance, Status status, const char *category, const char *message)
{
    fmi2CallbackLogger logger = (fmi2CallbackLogger)instance->host_logger;
    if (logger != NULL) {
        logger(instance->host_environment, instance->name, (fmi2Status)status, category, "%s", message);
    }
}

const char *fmi2GetTypesPlatform(void)
{
    return fmi2TypesPlatform;
}

const char *fmi2GetVersion(void)
{
    return fmi2Version;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible UNUSED, fmi2Boolean loggingOn)
{
    void (*logger)(void) = functions != NULL ? (void (*)(void))functions->logger : NULL;
    void *environment = functions != NULL ? functions->componentEnvironment : NULL;
    char *resources;
    Instance *instance;
    if (fmuType != fmi2CoSimulation && fmuType != fmi2ModelExchange) {
        if (logger != NULL) {
            ((fmi2CallbackLogger)logger)(environment, instanceName ? instanceName : "", fmi2Error, "logStatusError",
                                         "%s", "fmi2Instantiate: fmuType is neither fmi2ModelExchange nor "
                                         "fmi2CoSimulation");
        }
        return NULL;
    }
    /* a file URI gives the resources folder; NULL or another scheme: none */
    resources = resource_folder_of_uri(fmuResourceLocation);
    instance = instance_new(instanceName, fmuGUID, "fmi2", emit, logger, environment, resources);
    free(resources);
    if (instance != NULL) {
        instance->model_exchange = fmuType == fmi2ModelExchange;
        instance->logging_on = loggingOn != fmi2False;
    }
    return instance;
}

void fmi2FreeInstance(fmi2Component c)
{
    instance_free((Instance *)c);
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
ON_INSTANCE(fmi2, instance_set_debug_logging(instance, "SetDebugLogging", loggingOn != fmi2False, nCategories,
                                             categories))

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined UNUSED, fmi2Real tolerance UNUSED,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined UNUSED, fmi2Real stopTime UNUSED)
{
    INSTANCE(c, fmi2Error)
    if (!instance_allows(instance, MODE_BIT(MODE_INSTANTIATED), "SetupExperiment")) {
        return fmi2Error;
    }
    return (fmi2Status)instance_set_start_time(instance, "SetupExperiment", startTime);
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    INSTANCE(c, fmi2Error)
    if (!instance_allows(instance, MODE_BIT(MODE_INSTANTIATED), "EnterInitializationMode")) {
        return fmi2Error;
    }
    instance->mode = MODE_INITIALIZATION;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c)
ON_INSTANCE(fmi2, instance_exit_initialization(instance))

fmi2Status fmi2Terminate(fmi2Component c)
ON_INSTANCE(fmi2, instance_terminate(instance))

fmi2Status fmi2Reset(fmi2Component c)
ON_INSTANCE(fmi2, instance_reset(instance))

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
ON_INSTANCE(fmi2, instance_get_real(instance, "GetReal", vr, nvr, value))

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[])
ON_INSTANCE(fmi2, instance_get_integer(instance, "GetInteger", vr, nvr, value))

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[])
ON_INSTANCE(fmi2, instance_get_boolean(instance, "GetBoolean", vr, nvr, value, sizeof(fmi2Boolean)))

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[])
ON_INSTANCE(fmi2, instance_get_string(instance, "GetString", vr, nvr, value))

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[])
ON_INSTANCE(fmi2, instance_set_real(instance, "SetReal", vr, nvr, value))

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[])
ON_INSTANCE(fmi2, instance_set_integer(instance, "SetInteger", vr, nvr, value))

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[])
ON_INSTANCE(fmi2, instance_set_boolean(instance, "SetBoolean", vr, nvr, value, sizeof(fmi2Boolean)))

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[])
ON_INSTANCE(fmi2, instance_set_string(instance, "SetString", vr, nvr, value))

FMU_STATE_FUNCTIONS(fmi2, fmi2Component, FMUstate, DeSerialize)

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[])
ON_INSTANCE(fmi2, derivatives_get(instance, "GetDirectionalDerivative", vUnknown_ref, nUnknown, vKnown_ref, nKnown,
                                  dvKnown, nKnown, dvUnknown, nUnknown, 0))

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
ON_INSTANCE(fmi2, instance_set_input_derivatives(instance, "SetRealInputDerivatives", vr, nvr, order, value))

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[] UNUSED, size_t nvr UNUSED,
                                        const fmi2Integer order[] UNUSED, fmi2Real value[] UNUSED)
ON_INSTANCE(fmi2, instance_unsupported(instance, "GetRealOutputDerivatives"))

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint UNUSED)
{
    INSTANCE(c, fmi2Error)
    if (!instance_is(instance, 0, "DoStep") || !instance_allows(instance, MODE_BIT(MODE_STEP), "DoStep")) {
        return fmi2Error;
    }
    return (fmi2Status)instance_do_step(instance, currentCommunicationPoint, communicationStepSize);
}

/* ---- Model Exchange --------------------------------------------------------------------- */

fmi2Status fmi2EnterEventMode(fmi2Component c)
ON_INSTANCE(fmi2, model_exchange_enter_mode(instance, "EnterEventMode", 1))

/* No events: nothing to update, no next event. */
fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *eventInfo)
{
    INSTANCE(c, fmi2Error)
    if (!model_exchange_call(instance, "NewDiscreteStates", eventInfo != NULL, 1)) {
        return fmi2Error;
    }
    eventInfo->newDiscreteStatesNeeded = fmi2False;
    eventInfo->terminateSimulation = fmi2False;
    eventInfo->nominalsOfContinuousStatesChanged = fmi2False;
    eventInfo->valuesOfContinuousStatesChanged = fmi2False;
    eventInfo->nextEventTimeDefined = fmi2False;
    eventInfo->nextEventTime = 0.0;
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c)
ON_INSTANCE(fmi2, model_exchange_enter_mode(instance, "EnterContinuousTimeMode", 0))

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetFMUStatePriorToCurrentPoint UNUSED,
                                       fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation)
{
    INSTANCE(c, fmi2Error)
    if (!model_exchange_call(instance, "CompletedIntegratorStep",
                             enterEventMode != NULL && terminateSimulation != NULL, 0)) {
        return fmi2Error;
    }
    *enterEventMode = fmi2False;
    *terminateSimulation = fmi2False;
    return fmi2OK;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time)
ON_INSTANCE(fmi2, model_exchange_set_time(instance, "SetTime", time))

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx)
ON_INSTANCE(fmi2, model_exchange_set_states(instance, "SetContinuousStates", x, nx))

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real derivatives[], size_t nx)
ON_INSTANCE(fmi2, model_exchange_get_derivatives(instance, "GetDerivatives", derivatives, nx))

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real eventIndicators[] UNUSED, size_t ni)
ON_INSTANCE(fmi2, model_exchange_get_event_indicators(instance, "GetEventIndicators", ni))

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx)
ON_INSTANCE(fmi2, model_exchange_get_states(instance, "GetContinuousStates", x, nx))

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x_nominal[], size_t nx)
ON_INSTANCE(fmi2, model_exchange_get_nominals(instance, "GetNominalsOfContinuousStates", x_nominal, nx))

fmi2Status fmi2CancelStep(fmi2Component c)
ON_INSTANCE(fmi2, instance_unsupported(instance, "CancelStep"))

/* Only what the standard defines for a finished step is available: the last successful time and
 * fmi2Terminated (true after a refused step, until a step is taken); any other query gets fmi2Discard. */
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s UNUSED, fmi2Status *value UNUSED)
ON_INSTANCE(fmi2, fmi2Discard)

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    INSTANCE(c, fmi2Error)
    if (s != fmi2LastSuccessfulTime || value == NULL) {
        return fmi2Discard;
    }
    *value = instance->data.time;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s UNUSED, fmi2Integer *value UNUSED)
ON_INSTANCE(fmi2, fmi2Discard)

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    INSTANCE(c, fmi2Error)
    if (s != fmi2Terminated || value == NULL) {
        return fmi2Discard;
    }
    *value = instance->terminated ? fmi2True : fmi2False;
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s UNUSED, fmi2String *value UNUSED)
ON_INSTANCE(fmi2, fmi2Discard)
