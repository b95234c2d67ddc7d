/* Model Exchange over the shared core: the host's solver integrates the model's continuous states
 * (ModelSpec.states: the input shaft's angle, the source's phase), the model gives their
 * derivatives and its outputs at any time, states and inputs.
 *
 * After initialisation an instance is in event mode (``event_mode``) or continuous-time mode, both
 * MODE_STEP of the co-simulation's modes, so that values, FMU states and refusals work as there.
 * The outputs are evaluated when a value is got after a time, state or input was set (``stale``),
 * with the checks of a co-simulation step: a parameter or input the step would refuse, or an
 * output that is not finite or beyond its bounds, is refused with the same words and fmi2Discard /
 * fmi3Discard, the values left as they were. The model keeps no history between evaluations: its
 * internal state is reset before each (the Cardan joint's alpha_in, a difference of two samples in
 * co-simulation, is 0; the tripod's rates from samples are 0 and its exact solver starts cold).
 * The models have no events: no event indicators, and event mode changes nothing.
 */
#include <math.h>
#include <stdio.h>

#include "fmu_instance.h"

#if MODEL_STATE_COUNT > 0
#define STATE_SLOTS MODEL_STATE_COUNT
#define STATE(data, k) ((data)->real_value[model_states[k]])
#define DERIVATIVE(data, k) ((data)->real_value[model_state_derivatives[k]])
#define NOMINAL(k) (model_state_nominals[k])
#define STATE_NAME(k) (model_variables[model_states[k]].name)
#else /* no state: the loops over them run zero times */
#define STATE_SLOTS 1
#define STATE(data, k) ((data)->real_value[0])
#define DERIVATIVE(data, k) ((data)->real_value[0])
#define NOMINAL(k) 1.0
#define STATE_NAME(k) ""
#endif

int instance_is(Instance *instance, int model_exchange, const char *function)
{
    if (instance->model_exchange != model_exchange) {
        instance_fail(instance, instance->fmi_prefix, function, " is a ",
                      model_exchange ? "Model Exchange" : "co-simulation", " function and this instance was "
                      "instantiated for ", model_exchange ? "co-simulation" : "Model Exchange", (const char *)NULL);
        return 0;
    }
    return 1;
}

static int model_exchange_allows(Instance *instance, const char *function)
{
    return instance_is(instance, 1, function);
}

void model_exchange_evaluate(Instance *instance, ModelData *data)
{
    Messages *out = &instance->messages;
    double states[STATE_SLOTS];
    char shown[40];
    Failure failure;
    int i;
    out->count = 0;
    instance_parameter_errors(instance, data);
    input_errors(data, out);
    if (out->count) {
        return;
    }
    for (i = 0; i < MODEL_STATE_COUNT; i++) {
        states[i] = STATE(data, i);
    }
    if (model_hooks.reset_internal != NULL) {
        model_hooks.reset_internal(data);
    }
    failure = model_hooks.evaluate(data, data->time);
    for (i = 0; i < MODEL_STATE_COUNT; i++) { /* a model of time alone computes its state too: the solver's */
        STATE(data, i) = states[i];
    }
    if (failure.kind == ERROR_NONE) {
        output_errors(data, out, &failure);
    }
    if (failure.kind != ERROR_NONE) {
        python_float_repr(data->time, shown, sizeof shown);
        messages_add(out, "the outputs at t = ", shown, " s could not be computed (", ERROR_KIND_NAME(failure.kind),
                     ": ", failure.message, ")", (const char *)NULL);
    }
}

/* The outputs and derivatives at the instance's time, states and inputs, if any of them changed. */
Status model_exchange_update(Instance *instance)
{
    StepUndo undo;
    if (!instance->model_exchange || !instance->stale || instance->mode != MODE_STEP) {
        return STATUS_OK;
    }
    if (model_hooks.evaluate == NULL) { /* a C port without the hook: no Model Exchange, never a crash */
        return instance_fail(instance, instance->fmi_prefix, ": ", MODEL_NAME, "'s C port gives no evaluate hook, "
                             "which Model Exchange needs", (const char *)NULL);
    }
    step_undo_keep(&instance->data, &undo);
    model_exchange_evaluate(instance, &instance->data);
    if (instance->messages.count) {
        step_undo_restore(&instance->data, &undo);
    }
    instance->stale = instance->messages.count > 0;
    return instance_refusal(instance);
}

/* 1 when ``function`` may read or write the ``n`` values of ``array`` now, ``expected`` of them. */
static int continuous_allows(Instance *instance, const char *function, const void *array, size_t n, size_t expected)
{
    char count[24];
    if (!model_exchange_allows(instance, function) ||
        !instance_allows(instance, MODE_BIT(MODE_INITIALIZATION) | MODE_BIT(MODE_STEP), function)) {
        return 0;
    }
    if (n > 0 && array == NULL) {
        instance_fail(instance, instance->fmi_prefix, function, ": null array", (const char *)NULL);
        return 0;
    }
    if (n != expected) {
        snprintf(count, sizeof count, "%lu", (unsigned long)expected);
        instance_fail(instance, instance->fmi_prefix, function, ": the model has ", count, " continuous states",
                      (const char *)NULL);
        return 0;
    }
    return 1;
}

Status model_exchange_set_time(Instance *instance, const char *function, double time)
{
    char shown[40];
    if (!model_exchange_allows(instance, function) || !instance_allows(instance, MODE_BIT(MODE_STEP), function)) {
        return STATUS_ERROR;
    }
    if (!isfinite(time)) {
        python_float_repr(time, shown, sizeof shown);
        return instance_fail(instance, instance->fmi_prefix, function, ": time = ", shown, " is not finite",
                             (const char *)NULL);
    }
    instance->data.time = time;
    instance->stale = 1;
    return STATUS_OK;
}

/* FMI 2.0 sets the states in continuous-time mode only, FMI 3.0 in event mode too; not before initialisation
 * ends (ExitInitializationMode computes them from the start values: a state set before would be lost). A
 * state that is not finite is refused (Discard, none set): no evaluation takes it, and a state kept is one
 * the host may read back. */
Status model_exchange_set_states(Instance *instance, const char *function, const double x[], size_t n)
{
    char index[24], shown[40];
    int i;
    if (!continuous_allows(instance, function, x, n, MODEL_STATE_COUNT)) {
        return STATUS_ERROR;
    }
    if (instance->mode != MODE_STEP || (instance->event_mode && instance->fmi_prefix[3] == '2')) {
        return instance_fail(instance, instance->fmi_prefix, function, " is not allowed in ",
                             instance->mode != MODE_STEP ? "InitializationMode" : "EventMode",
                             instance->fmi_prefix[3] == '2' ? " (only in ContinuousTimeMode)"
                                                            : " (only in ContinuousTimeMode or EventMode)",
                             (const char *)NULL);
    }
    instance->messages.count = 0;
    for (i = 0; i < MODEL_STATE_COUNT; i++) {
        if (!isfinite(x[i])) {
            snprintf(index, sizeof index, "%d", i);
            python_float_repr(x[i], shown, sizeof shown);
            messages_add(&instance->messages, "the continuous state x[", index, "] (",
                         STATE_NAME(i), ") = ", shown,
                         " is not finite; the states were not set", (const char *)NULL);
            return instance_refusal(instance);
        }
    }
    for (i = 0; i < MODEL_STATE_COUNT; i++) {
        STATE(&instance->data, i) = x[i];
    }
    instance->stale = 1;
    return STATUS_OK;
}

Status model_exchange_get_states(Instance *instance, const char *function, double x[], size_t n)
{
    Status status;
    const ModelData *values;
    int i;
    if (!continuous_allows(instance, function, x, n, MODEL_STATE_COUNT)) {
        return STATUS_ERROR;
    }
    values = instance_readable(instance, &status);
    for (i = 0; i < MODEL_STATE_COUNT; i++) {
        x[i] = STATE(values, i);
    }
    return status;
}

Status model_exchange_get_derivatives(Instance *instance, const char *function, double dx[], size_t n)
{
    Status status, initial;
    const ModelData *values;
    int i;
    if (!continuous_allows(instance, function, dx, n, MODEL_STATE_COUNT)) {
        return STATUS_ERROR;
    }
    status = model_exchange_update(instance);
    values = instance_readable(instance, &initial);
    for (i = 0; i < MODEL_STATE_COUNT; i++) {
        dx[i] = DERIVATIVE(values, i);
    }
    return status > initial ? status : initial;
}

/* Nominal values: State.nominal of the spec, the states' typical magnitudes (model_state_nominals). */
Status model_exchange_get_nominals(Instance *instance, const char *function, double nominals[], size_t n)
{
    int i;
    if (!continuous_allows(instance, function, nominals, n, MODEL_STATE_COUNT)) {
        return STATUS_ERROR;
    }
    for (i = 0; i < MODEL_STATE_COUNT; i++) {
        nominals[i] = NOMINAL(i);
    }
    return STATUS_OK;
}

Status model_exchange_get_event_indicators(Instance *instance, const char *function, size_t n)
{
    return continuous_allows(instance, function, "", n, 0) ? STATUS_OK : STATUS_ERROR;
}

/* 1 when the instance is in event mode (``event`` 1) or continuous-time mode (0); else Error with the reason. */
static int in_mode(Instance *instance, const char *function, int event)
{
    if (instance->event_mode == event) {
        return 1;
    }
    instance_fail(instance, instance->fmi_prefix, function, " is not allowed in ",
                  event ? "ContinuousTimeMode (only in EventMode)" : "EventMode (only in ContinuousTimeMode)",
                  (const char *)NULL);
    return 0;
}

int model_exchange_call(Instance *instance, const char *function, int outputs_given, int event)
{
    if (!model_exchange_allows(instance, function) || !instance_allows(instance, MODE_BIT(MODE_STEP), function) ||
        !in_mode(instance, function, event)) {
        return 0;
    }
    if (!outputs_given) {
        instance_fail(instance, instance->fmi_prefix, function, ": null output argument", (const char *)NULL);
        return 0;
    }
    return 1;
}

/* Event mode (``event``) or continuous-time mode: the models have no events, so neither changes a value.
 * Continuous-time mode is entered from event mode only. */
Status model_exchange_enter_mode(Instance *instance, const char *function, int event)
{
    if (!model_exchange_allows(instance, function) || !instance_allows(instance, MODE_BIT(MODE_STEP), function) ||
        (!event && !in_mode(instance, function, 1))) {
        return STATUS_ERROR;
    }
    instance->event_mode = event;
    return STATUS_OK;
}
