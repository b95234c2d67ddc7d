/* FMI 2.0 co-simulation entry points over the shared core (fmu_instance.c).
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
                              fmi2Boolean visible UNUSED, fmi2Boolean loggingOn UNUSED)
{
    void (*logger)(void) = functions != NULL ? (void (*)(void))functions->logger : NULL;
    void *environment = functions != NULL ? functions->componentEnvironment : NULL;
    char *resources;
    Instance *instance;
    if (fmuType != fmi2CoSimulation) {
        if (logger != NULL) {
            ((fmi2CallbackLogger)logger)(environment, instanceName ? instanceName : "", fmi2Error, "logStatusError",
                                         "%s", "fmi2Instantiate: this FMU offers co-simulation only");
        }
        return NULL;
    }
    /* a file URI gives the resources folder; NULL or another scheme: none */
    resources = resource_folder_of_uri(fmuResourceLocation);
    instance = instance_new(instanceName, fmuGUID, "fmi2", emit, logger, environment, resources);
    free(resources);
    return instance;
}

void fmi2FreeInstance(fmi2Component c)
{
    instance_free((Instance *)c);
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn UNUSED, size_t nCategories,
                               const fmi2String categories[])
ON_INSTANCE(fmi2, instance_set_debug_logging(instance, "SetDebugLogging", nCategories, categories))

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

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[] UNUSED,
                                        size_t nUnknown UNUSED,
                                        const fmi2ValueReference vKnown_ref[] UNUSED, size_t nKnown UNUSED,
                                        const fmi2Real dvKnown[] UNUSED, fmi2Real dvUnknown[] UNUSED)
ON_INSTANCE(fmi2, instance_unsupported(instance, "GetDirectionalDerivative"))

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
    if (!instance_allows(instance, MODE_BIT(MODE_STEP), "DoStep")) {
        return fmi2Error;
    }
    return (fmi2Status)instance_do_step(instance, currentCommunicationPoint, communicationStepSize);
}

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
